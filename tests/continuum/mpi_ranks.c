/* mpi_ranks N: MPI starts on N ranks (run through tests/mpirun.sh N) and
 * every rank sees N; a message passes from every rank to rank 0.  Exit 0,
 * else 1 with one line on stderr. */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    if (MPI_Init(&argc, &argv) != MPI_SUCCESS) {
        fprintf(stderr, "mpi_ranks: MPI_Init failed\n");
        return 1;
    }
    int rank = -1, size = -1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    const int want = argc > 1 ? atoi(argv[1]) : -1;
    int ok = size == want, sum = 0;
    MPI_Reduce(&rank, &sum, 1, MPI_INT, MPI_SUM, 0, MPI_COMM_WORLD);
    if (rank == 0 && sum != size * (size - 1) / 2)
        ok = 0;
    if (!ok)
        fprintf(stderr, "mpi_ranks: rank %d: %d ranks (expected %d), rank sum %d\n", rank, size, want, sum);
    MPI_Finalize();
    return ok ? 0 : 1;
}
