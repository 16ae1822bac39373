# The 2D solver (issue 14, continuum/twod/) and the HDF5 the whole build
# uses (docs/build.md).
#
# EKM_2D: AUTO (default) builds the 2D solver when PETSc is found
# (pkg-config module PETSc), ON requires it, OFF never builds it.  Sets
# EKM_HAVE_2D (ON/OFF), the imported targets PkgConfig::PETSC and
# MPI::MPI_C when ON, and the interface target ekm_hdf5 (HDF5's headers
# and libraries, MPI's with a parallel HDF5) that every target using HDF5
# links.
#
# HDF5: Debian's PETSc links the OpenMPI build of HDF5 (libhdf5_openmpi).
# A program linking PETSc and the serial HDF5 would carry two HDF5
# libraries, so with the 2D solver the WHOLE build uses the OpenMPI HDF5
# (same API and file format; the programs that never call MPI_Init use it
# serially), and without it the serial HDF5.

set(EKM_2D AUTO CACHE STRING "Build the 2D solver (PETSc + MPI): AUTO (when PETSc is found), ON, OFF")
set_property(CACHE EKM_2D PROPERTY STRINGS AUTO ON OFF)
string(TOUPPER "${EKM_2D}" ekm_2d_choice)
if(ekm_2d_choice MATCHES "^(ON|YES|TRUE|1)$")
  set(ekm_2d_choice ON)
elseif(ekm_2d_choice MATCHES "^(OFF|NO|FALSE|0)$")
  set(ekm_2d_choice OFF)
elseif(NOT ekm_2d_choice STREQUAL "AUTO")
  message(FATAL_ERROR "EKM_2D=${EKM_2D}: expected AUTO, ON or OFF")
endif()

set(EKM_HAVE_2D OFF)
if(NOT ekm_2d_choice STREQUAL "OFF")
  pkg_check_modules(PETSC QUIET IMPORTED_TARGET PETSc)
  if(PETSC_FOUND)
    set(EKM_HAVE_2D ON)
  elseif(ekm_2d_choice STREQUAL "ON")
    message(FATAL_ERROR "EKM_2D=ON, but PETSc was not found (pkg-config module PETSc): install the 2D "
                        "solver's packages with `scripts/deps.sh ekm2d`, then re-run cmake (or -DEKM_2D=OFF)")
  endif()
endif()

# Which HDF5: FindHDF5 caches what it found, so a change of choice in an
# existing build folder forgets the old one first.
if(DEFINED EKM_HDF5_PARALLEL_CACHED AND NOT EKM_HDF5_PARALLEL_CACHED STREQUAL EKM_HAVE_2D)
  get_cmake_property(ekm_cache_vars CACHE_VARIABLES)
  foreach(v IN LISTS ekm_cache_vars)
    if(v MATCHES "^HDF5_")
      unset(${v} CACHE)
    endif()
  endforeach()
endif()
set(EKM_HDF5_PARALLEL_CACHED ${EKM_HAVE_2D} CACHE INTERNAL "EKM_HAVE_2D the cached HDF5 was found for")

set(HDF5_PREFER_PARALLEL ${EKM_HAVE_2D})
find_package(HDF5 REQUIRED COMPONENTS C)
add_library(ekm_hdf5 INTERFACE)
target_include_directories(ekm_hdf5 INTERFACE ${HDF5_INCLUDE_DIRS})
target_link_libraries(ekm_hdf5 INTERFACE ${HDF5_C_LIBRARIES})
target_compile_definitions(ekm_hdf5 INTERFACE ${HDF5_DEFINITIONS})

# The HDF5 library's folder (the first libhdf5 of HDF5_C_LIBRARIES).
set(ekm_hdf5_dir "")
foreach(lib IN LISTS HDF5_C_LIBRARIES)
  get_filename_component(name "${lib}" NAME)
  if(name MATCHES "^libhdf5(_openmpi|_serial)?\\.(so|a)")
    get_filename_component(ekm_hdf5_dir "${lib}" DIRECTORY)
    break()
  endif()
endforeach()

if(EKM_HAVE_2D)
  find_package(MPI REQUIRED COMPONENTS C)
  # the parallel HDF5's headers include mpi.h
  target_link_libraries(ekm_hdf5 INTERFACE MPI::MPI_C)
  set(EKM_HDF5_MPI_DIR "/usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/hdf5/openmpi" CACHE PATH
      "Folder of the OpenMPI HDF5 that PETSc links (the 2D build uses it everywhere)")
  if(NOT HDF5_IS_PARALLEL OR NOT ekm_hdf5_dir STREQUAL EKM_HDF5_MPI_DIR)
    message(FATAL_ERROR "the 2D solver (EKM_2D) needs the build to use the OpenMPI HDF5 that PETSc links "
                        "(${EKM_HDF5_MPI_DIR}), but CMake found HDF5 in '${ekm_hdf5_dir}' (parallel: "
                        "${HDF5_IS_PARALLEL}): install libhdf5-openmpi-dev (scripts/deps.sh ekm2d) and "
                        "configure a fresh build folder, or -DEKM_2D=OFF")
  endif()
  message(STATUS "ekm HDF5: the OpenMPI HDF5 ${HDF5_VERSION} (${ekm_hdf5_dir}) for the whole build: "
                 "the 2D solver's PETSc ${PETSC_VERSION} links it (docs/build.md)")
else()
  if(ekm_2d_choice STREQUAL "OFF")
    set(ekm_why "EKM_2D=OFF")
  else()
    set(ekm_why "PETSc not found, the 2D solver is not built (scripts/deps.sh ekm2d, then re-run cmake)")
  endif()
  message(STATUS "ekm HDF5: the serial HDF5 ${HDF5_VERSION} (${ekm_hdf5_dir}): ${ekm_why} (docs/build.md)")
endif()

# Why ekm has no 2D solver, for its exit-7 message (continuum/main.c).
if(EKM_HAVE_2D AND NOT EXISTS ${CMAKE_SOURCE_DIR}/continuum/twod/run2d.c)
  set(EKM_NO_2D_REASON "its entry continuum/twod/run2d.c is not written yet, issue 14")
elseif(ekm_2d_choice STREQUAL "OFF")
  set(EKM_NO_2D_REASON "configured with -DEKM_2D=OFF")
else()
  set(EKM_NO_2D_REASON "PETSc was not found: scripts/deps.sh ekm2d, then re-run cmake")
endif()
