#!/usr/bin/env bash
# run.sh: run one DEM scenario in one engine at one size.
#
#   scripts/dem/run.sh [-f] [-n NP] [-s key=value]... SCENARIO ENGINE SIZE
#
#   SCENARIO  name of scenarios/<name>.ini (must have a [dem] section), or
#             'collision' with -c FILE: binary-collision restitution test
#             using the contact parameters of FILE's [dem] section
#   ENGINE    liggghts | lammps
#   SIZE      smoke | ref (selects the '<size>.' keys of [dem])
#   -n NP     MPI ranks (default 1; NP > 1 runs through mpirun)
#   -f        overwrite a finished run (FORCE=1 in make)
#   -s k=v    override a [dem] key for this run (repeatable): passed to the
#             scenario reader as --set dem.k=v, whatever it is (a bad or
#             unknown key or value, or no '=', is the reader's error: one
#             line naming the key, exit 2)
#   -o DIR    output root (default runs/)
#   -l        list the sweep points, one "TAG|name value ..." per line (TAG
#             empty: a single case in the top directory), and run nothing
#   -p        print the deck variables of every point ("== TAG" and then
#             vars.txt as it would be written), and run nothing
#   -P TAG    run (list, print) only the sweep point TAG (repeatable; a TAG
#             the scenario lacks: exit 1 naming it)
#
# Every value comes from the resolved scenario, `ekmscenario FILE --engine
# ENGINE --size SIZE --json` (docs/resolved-scenario.md; EKMSCENARIO= names
# the ekmscenario binary, default build/scenario/ekmscenario; EKMCOMPARE= the ekmcompare binary,
# default beside it, whose `steady` command judges the monitor series): shared values (geometry, gravity,
# wall speeds, inflow) from its continuum sections, DEM-only values from
# [dem], the sweep points from its points; docs/dem.md lists the mapping to
# the deck variables. Every case writes
# runs/<scenario>/<engine>-<size>[/<point>]/ with the deck (deck.in), the
# variables (vars.txt), the engine log (log.txt), its screen output
# (screen.txt), dumps, a monitor series (monitor.txt) and run.json, which
# records the status and what the run produced: "dumps", the frames, bytes
# and sha256 of every dump (scripts/dem/dump_record.sh). A finished run
# whose dumps no longer match that record is run again.
#
# Exit status (docs/exit-codes.md): 0 ok (or already done), 1 usage,
# 2 scenario error (the reader's message), 3 output folder not writable,
# 4 run failed (deck error, lost atoms, NaN, timeout, missing completion
# marker), 6 run finished but not steady where steadiness is required,
# 7 engine, mpirun or ekm missing, or scenario not supported by this engine
# (dem_inputs/<engine>/<scenario>.unsupported). With several points the
# status of the worst: a failed run (4) before a not steady one (6).
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
prog=run.sh

usage() { echo "$prog: $*" >&2; exit 1; }
die() { echo "$prog: $*" >&2; exit 2; }

force=0; np=1; outroot="$root/runs"; sets=(); cfile=""; list=0; printvars=0
only=()
while getopts "flpn:s:o:c:P:h" opt; do
  case $opt in
    f) force=1 ;;
    l) list=1 ;;
    p) printvars=1 ;;
    n) np=$OPTARG ;;
    s) sets+=("$OPTARG") ;;
    o) outroot=$OPTARG ;;
    c) cfile=$OPTARG ;;
    P) only+=("$OPTARG") ;;
    h) sed -n '2,42p' "$0"; exit 0 ;;
    *) usage "bad option (see -h)" ;;
  esac
done
shift $((OPTIND - 1))
[ $# -eq 3 ] || usage "usage: run.sh [-f] [-n NP] [-s key=value] SCENARIO ENGINE SIZE"
scen=$1; engine=$2; size=$3
case $engine in liggghts|lammps) ;; *) usage "unknown engine '$engine' (liggghts, lammps)" ;; esac
case $size in smoke|ref) ;; *) usage "unknown size '$size' (smoke, ref)" ;; esac
[[ $np =~ ^[1-9][0-9]*$ ]] || usage "NP must be a positive integer, got '$np'"
dry=$(( list | printvars ))

if [ "$scen" = collision ]; then
  ini=${cfile:-$root/scenarios/chute.ini}
else
  [[ $scen =~ ^[A-Za-z0-9_-]+$ ]] || usage "bad scenario name '$scen'"
  ini=$root/scenarios/$scen.ini
fi
[ -r "$ini" ] || die "no scenario file $ini"
if [ -r "$root/dem_inputs/$engine/$scen.unsupported" ]; then
  echo "$prog: UNSUPPORTED: $scen in $engine:" >&2
  sed 's/^/  /' "$root/dem_inputs/$engine/$scen.unsupported" >&2
  exit 7
fi
deck=$root/dem_inputs/$engine/$scen.in
[ -r "$deck" ] || { echo "$prog: no deck $deck: $engine cannot run '$scen'" >&2; exit 7; }

# --- the resolved scenario ------------------------------------------------
ekmscenario=${EKMSCENARIO:-$root/build/scenario/ekmscenario}
[ -x "$ekmscenario" ] || { echo "$prog: ekmscenario not built: run make build (no executable $ekmscenario)" >&2; exit 7; }
ekmcompare=${EKMCOMPARE:-$(dirname "$(dirname "$ekmscenario")")/compare/ekmcompare}
[ -x "$ekmcompare" ] || { echo "$prog: ekmcompare not built: run make build (no executable $ekmcompare)" >&2; exit 7; }
command -v jq > /dev/null || { echo "$prog: jq not installed (scripts/deps.sh base)" >&2; exit 7; }
setargs=()
# every -s KEY=VALUE goes to the reader as it is written: its rules, its
# error line naming the key, its exit status 2 (one without a key and '='
# is refused here, naming -s, the option the user wrote)
for s in "${sets[@]+"${sets[@]}"}"; do
  [[ $s == [A-Za-z]*=* ]] || { echo "$prog: -s '$s': expected KEY=VALUE (a [dem] key, e.g. -s t_flow=2)" >&2; exit 2; }
  setargs+=(--set "dem.$s")
done
resolved=$("$ekmscenario" "$ini" --engine "$engine" --size "$size" "${setargs[@]+"${setargs[@]}"}" --json)
rc=$?
[ $rc -eq 0 ] || exit $rc   # the reader named file, line and key on stderr
# K[section.key] = value as written; F[...] = where it came from
declare -A K=() F=()
while IFS=$'\t' read -r k v f; do K[$k]=$v; F[$k]=$f; done < <(
  jq -r '.keys | to_entries[] | [.key, .value.value, .value.from] | @tsv' <<< "$resolved")
has_dem=0
for k in "${!F[@]}"; do
  [[ $k == dem.* ]] && [ "${F[$k]}" != default ] && { has_dem=1; break; }
done
[ $has_dem -eq 1 ] || die "$ini: no [dem] section"
# need SECTION.KEY...: each key is in the resolved scenario, else a loud
# error (exit 2) naming it; called in the main shell, so that it exits the
# runner (the values are then read from K directly)
need() {
  local k
  for k; do
    [ -n "${K[$k]+set}" ] || die "$ini: [${k%%.*}] ${k#*.}: missing key"
  done
}
num() { # num NAME VALUE: check VALUE is a number
  [[ $2 =~ ^[-+]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?$ ]] ||
    { echo "$prog: $ini: $1: expected a number, got '$2'" >&2; exit 2; }
}
calc() { awk "BEGIN { printf \"%.10g\", $* }"; }

# --- engine ------------------------------------------------------------
case $engine in   # LIGGGHTS_EXE, LAMMPS_EXE override the binaries
  liggghts) exe=${LIGGGHTS_EXE:-liggghts} ;;
  lammps)   exe=${LAMMPS_EXE:-lmp} ;;
esac
[ $dry -eq 1 ] || command -v "$exe" >/dev/null ||
  { echo "$prog: engine '$exe' not found (run scripts/deps.sh dem)" >&2; exit 7; }
if [ "$np" -gt 1 ] && [ $dry -eq 0 ]; then
  command -v mpirun >/dev/null ||
    { echo "$prog: NP=$np needs mpirun (openmpi-bin)" >&2; exit 7; }
fi
[ $dry -eq 1 ] || version=$("$exe" -h 2>/dev/null | grep -m1 -oE '(LIGGGHTS-PUBLIC [0-9.]+|[0-9]+ [A-Z][a-z]{2} [0-9]{4}( - Update [0-9]+)?)')

# --- variables common to every deck ------------------------------------
declare -a vars=()
addv() { num "$1" "$2"; vars+=("$1" "$2"); }
addk() { need "$2"; addv "$1" "${K[$2]}"; }   # addk NAME SECTION.KEY
need dem.diameter; d=${K[dem.diameter]};  addv d "$d"
addk spread dem.spread
addk rho material.rho_p
addk E dem.youngs
need dem.poisson; nu=${K[dem.poisson]};  addv nu "$nu"
addk e_in dem.restitution_input
addk mu dem.friction
# LAMMPS: tangential/normal damping ratio that reproduces LIGGGHTS's
# gamma_t/gamma_n = sqrt(S_t/S_n) = sqrt(2 (1-nu)/(2-nu)) (docs/dem.md).
[ "$engine" = lammps ] && addv xgt "$(calc "sqrt(2*(1-$nu)/(2-$nu))")"
addk dt dem.dt
need dem.seed; seed=${K[dem.seed]}; addv seed "$seed"
# seed2, seed3: the next primes after seed (LIGGGHTS accepts only primes > 10000)
nextprime() { awk -v s="$1" 'BEGIN { for (n = s + 1; ; n++) { p = 1
  for (k = 2; k * k <= n; k++) if (n % k == 0) { p = 0; break }
  if (p) { print n; exit } } }'; }
seed2=$(nextprime "$seed"); addv seed2 "$seed2"; addv seed3 "$(nextprime "$seed2")"
addk thermo_every dem.thermo_every
# With [dem] dump_strain (simple_shear_p) the reader gives every shear point
# its own dump_every, one frame every dump_strain of shear (the rates span
# 100x: a fixed step count would give 100x the frames); it is then a point
# variable, after the point's others.
point_dump=$(jq -r '.points[0].vars | has("dump_every")' <<< "$resolved")
[ "$point_dump" = true ] || addk dump_every dem.dump_every
lateral() { # lx, ly: [dem] lx, ly are in grain diameters
  local x y; need dem.lx dem.ly; x=${K[dem.lx]} y=${K[dem.ly]}
  num lx "$x"; num ly "$y"
  addv lx "$(calc "$x * $d")"; addv ly "$(calc "$y * $d")"
}

# --- scenario-specific variables ------------------------------------------
# pointvars: the deck variables each sweep point sets, in deck order (the
# values come from the resolved scenario's points)
pointvars=()
case $scen in
  collision) ;;
  filling)
    lateral
    addk lz domain.length
    addk g gravity.magnitude
    addk phi_in top.phi
    addk w_in top.w
    addk t_stop top.t_stop
    addk t_end dem.t_end ;;
  chute)
    lateral
    addk h initial.layer_height
    addk phi0 initial.phi
    addk g gravity.magnitude
    addk t_settle dem.t_settle
    addk t_flow dem.t_flow
    pointvars=(theta) ;;
  shear_cell)
    lateral
    addk gap domain.length
    addk phi0 initial.phi
    addk v_top top.velocity
    addk v_bot bottom.velocity
    addk pressure dem.pressure
    addk wall_damp dem.wall_damping
    addk t_compress dem.t_compress
    addk t_run dem.t_run ;;
  simple_shear)
    addk L domain.length
    addk t_compress dem.t_compress
    addk strain dem.strain
    pointvars=(phi rate) ;;
  simple_shear_p)
    addk L domain.length
    addk phi0 initial.phi
    addk t_compress dem.t_compress
    addk strain dem.strain
    addk p_gain dem.p_gain
    pointvars=(pressure rate) ;;
  sandpile)
    need dem.ly dem.pour_height
    num ly "${K[dem.ly]}"; num pour_height "${K[dem.pour_height]}"
    addv ly "$(calc "${K[dem.ly]} * $d")"
    addk lx domain.width
    addk lz domain.length
    addk g gravity.magnitude
    addk m_pile dem.pile_mass
    addk q_pour dem.pour_rate
    addk v_pour dem.pour_speed
    addv h_pour "$(calc "${K[dem.pour_height]} * $d")"
    need dem.plate_width dem.hopper_gap
    num plate_width "${K[dem.plate_width]}"; num hopper_gap "${K[dem.hopper_gap]}"
    addv lp "$(calc "${K[dem.plate_width]} * $d")"
    addv h_gap "$(calc "${K[dem.hopper_gap]} * $d")"
    addk n_stage dem.hopper_stages
    addk mu_r dem.rolling_friction
    addk t_end dem.t_end
    # the settling after t_end (docs/dem.md "Sand pile"): on in chunks of
    # dump_every steps while the pile on the plate has a kinetic energy per
    # mass >= rest_ke, until settle_max at the latest (= t_end: none)
    addk settle_max dem.settle_max
    addk rest_ke dem.rest_ke
    # [dem] timeout is the wall-time of a run to t_end: a run that may settle
    # on to settle_max gets it in proportion
    need dem.timeout; num timeout "${K[dem.timeout]}"
    run_scale=$(calc "${K[dem.settle_max]} / ${K[dem.t_end]}")
    pointvars=(source_width) ;;
  *) die "no variable mapping for scenario '$scen' (see docs/dem.md)" ;;
esac
[ "$point_dump" = true ] && pointvars+=(dump_every)

# --- sweep points: one "tag|name value name value ..." per case; tag '' = top dir
points=()
if [ "$scen" = collision ]; then
  points=("|")
else
  pv=$(printf '%s\n' "${pointvars[@]+"${pointvars[@]}"}" | jq -R . | jq -sc .)
  while IFS= read -r line; do points+=("$line"); done < <(
    jq -r --argjson pv "$pv" '.points[] | . as $p
      | "\(.tag)|" + ([$pv[] | select(. != "") | "\(.) \($p.vars[.] // error("point \($p.tag): no value for \(.)"))"] | join(" "))' <<< "$resolved") ||
    die "$ini: the resolved sweep points lack a deck variable"
  [ ${#points[@]} -gt 0 ] || die "$ini: no sweep points"
  for p in "${points[@]}"; do
    read -ra pset <<< "${p#*|}"
    for ((i = 0; i < ${#pset[@]}; i += 2)); do num "${pset[i]}" "${pset[i+1]}"; done
  done
fi
if [ ${#only[@]} -gt 0 ]; then # -P: the named points only, each one the scenario has
  kept=()
  for tag in "${only[@]}"; do
    found=0
    for p in "${points[@]}"; do [ "${p%%|*}" = "$tag" ] && { kept+=("$p"); found=1; }; done
    [ $found -eq 1 ] || usage "-P $tag: $scen has no sweep point $tag (run.sh -l lists them)"
  done
  points=("${kept[@]}")
fi
if [ $list -eq 1 ]; then printf '%s\n' "${points[@]}"; exit 0; fi
need dem.timeout; timeout_s=${K[dem.timeout]}
# a sand pile that may settle past t_end (settle_max > t_end): the limit
# scaled by settle_max / t_end, rounded up to whole seconds
if [ -n "${run_scale:-}" ]; then
  timeout_s=$(awk -v t="$timeout_s" -v r="$run_scale" 'BEGIN { x = t * (r > 1 ? r : 1); n = int(x); if (n < x) n++; print n }')
fi
need dem.require_steady; require_steady=${K[dem.require_steady]}
need dem.steady_tol; steady_tol=${K[dem.steady_tol]}

# --- run one case --------------------------------------------------------
json_escape() { sed -e 's/\\/\\\\/g' -e 's/"/\\"/g' | tr -d '\n'; }

run_case() { # run_case TAG "name value ..."
  local tag=$1 extra=$2 dir st=ok msg="" rc
  dir=$outroot/$scen/$engine-$size${tag:+/$tag}
  local -a all=("${vars[@]}") args=()
  local -a ex=()
  read -ra ex <<< "$extra"
  all+=("${ex[@]+"${ex[@]}"}")
  local i newvars=""
  for ((i = 0; i < ${#all[@]}; i += 2)); do
    newvars+=$(printf '%s = %s' "${all[i]}" "${all[i+1]}")$'\n'
    args+=(-var "${all[i]}" "${all[i+1]}")
  done
  if [ $printvars -eq 1 ]; then printf '== %s\n%s' "$tag" "$newvars"; return 0; fi
  # A finished run (ok, or complete but not steady) is kept unless forced
  # or its inputs changed (deck, includes, variables: compared by content,
  # so editing a comment or another section of the scenario file does not
  # redo an hour of DEM); its exit status is reported again.
  local same=1 f
  if [ -f "$dir/run.json" ]; then
    cmp -s "$deck" "$dir/deck.in" || same=0
    for f in "$root/dem_inputs/$engine/"*.inc; do
      [ -e "$f" ] && { cmp -s "$f" "$dir/${f##*/}" || same=0; }
    done
    [ "$newvars" = "$(cat "$dir/vars.txt" 2>/dev/null)"$'\n' ] || same=0
    [ $same -eq 0 ] && [ $force -eq 0 ] && echo "$prog: $dir: inputs changed (deck or variables): running again"
    # the dumps must still be what the run produced (run.json "dumps":
    # frames, bytes, sha256); one that changed after the run (truncated,
    # edited, removed) is not a finished run
    if [ $same -eq 1 ] && [ $force -eq 0 ]; then
      local chk
      if chk=$("$here/dump_record.sh" verify "$dir" 2>&1); then
        [ -z "$chk" ] || echo "$chk" >&2
      else
        echo "$chk" >&2
        echo "$prog: $dir: its dumps are not what the run produced: running again" >&2
        same=0
      fi
    fi
  fi
  if [ -f "$dir/run.json" ] && [ $force -eq 0 ] && [ $same -eq 1 ]; then
    if grep -q '"status": "ok"' "$dir/run.json"; then
      echo "$prog: $dir is done (status ok); FORCE=1 (-f) to redo"; return 0
    elif grep -q '"status": "not_steady"' "$dir/run.json"; then
      echo "$prog: $dir is done (status not_steady); FORCE=1 (-f) to redo" >&2; return 6
    fi
  fi
  rm -rf "$dir"; mkdir -p "$dir" || { echo "$prog: cannot create $dir" >&2; return 3; }
  cp "$deck" "$dir/deck.in"
  cp "$root/dem_inputs/$engine/"*.inc "$dir/" 2>/dev/null
  printf '%s' "$newvars" > "$dir/vars.txt"
  local -a cmd=()
  [ "$np" -gt 1 ] && cmd+=(mpirun --allow-run-as-root --oversubscribe -np "$np")
  cmd+=(stdbuf -o0 "$exe" -in deck.in -log log.txt -echo screen "${args[@]}")
  local cmdstr; cmdstr=$(printf '%q ' "${cmd[@]}")
  echo "$prog: $scen $engine $size${tag:+ $tag}: running in $dir"
  local t0 t1
  t0=$(date +%s.%N)
  ( cd "$dir" && timeout "$timeout_s" "${cmd[@]}" > screen.txt 2>&1 )
  rc=$?
  t1=$(date +%s.%N)
  local wall; wall=$(calc "$t1 - $t0")
  # --- loud failure detection ---
  if [ $rc -eq 124 ]; then st=timeout; msg="killed after ${timeout_s} s"
  elif grep -qi 'lost atoms' "$dir/screen.txt"; then
    st=lost_atoms; msg=$(grep -m1 -i 'lost atoms' "$dir/screen.txt")
  elif grep -qE '^ERROR|ERROR( on proc [0-9]+)?:' "$dir/screen.txt"; then
    st=deck_error; msg=$(grep -m1 -E 'ERROR' "$dir/screen.txt")
  elif [ $rc -ne 0 ]; then st=engine_failed; msg="exit status $rc"
  elif awk '/^ *Step /{t=1;next} /^Loop time/{t=0} t && tolower($0) ~ /(^|[ \t])[-+]?(nan|inf)([ \t]|$)/ {f=1} END{exit !f}' "$dir/screen.txt"; then
    st=nan; msg="NaN or Inf in thermo output"
  elif ! grep -q '^EKMDEM_DONE' "$dir/screen.txt"; then
    st=incomplete; msg="no completion marker (EKMDEM_DONE) in screen output"
  fi
  local natoms="null" steps="null"
  if grep -q '^EKMDEM_DONE' "$dir/screen.txt"; then
    natoms=$(grep -m1 '^EKMDEM_DONE' "$dir/screen.txt" | sed -n 's/.*natoms \([0-9]*\).*/\1/p')
    steps=$(grep -m1 '^EKMDEM_DONE' "$dir/screen.txt" | sed -n 's/.*steps \([0-9]*\).*/\1/p')
  fi
  # what the run produced: frames, bytes and sha256 of every dump, so that
  # a later step can tell a dump that changed after the run
  local dumps
  dumps=$("$here/dump_record.sh" record "$dir") || return 3
  # --- steady state: last quarter of the monitor series vs the one before ---
  local steady=null drift=null
  if [ "$st" = ok ] && [ -s "$dir/monitor.txt" ]; then
    # one definition of "steady" (compare/steadiness.c, docs/compare.md):
    # relative drift of the mean of the last quarter of the monitor series
    # against the quarter before, 4 significant digits, steady if <= tol
    local verdict
    verdict=$("$ekmcompare" steady "$dir/monitor.txt" --column 2 --tol "$steady_tol") ||
      { echo "$prog: $dir/monitor.txt: ekmcompare steady failed" >&2; return 4; }
    # the numbers as printed (jq would reformat them; '//' would drop false)
    drift=$(sed -n 's/.*"drift": *\([^,}]*\).*/\1/p' <<< "$verdict")
    steady=$(sed -n 's/.*"steady": *\([a-z]*\).*/\1/p' <<< "$verdict")
    if [ "$require_steady" = 1 ] && [ "$steady" != true ]; then
      st=not_steady; msg="monitor drift $drift > $steady_tol between the last two quarters"
    fi
  fi
  # the cleanup after && mv || runs when either fails (both leave no run.json)
  # shellcheck disable=SC2015
  {
    echo "{"
    echo "  \"scenario\": \"$scen\", \"engine\": \"$engine\", \"version\": \"$version\","
    echo "  \"size\": \"$size\", \"point\": \"$tag\", \"scenario_file\": \"${ini#"$root"/}\","
    echo "  \"command\": \"$(echo "$cmdstr" | json_escape)\","
    echo "  \"ranks\": $np, \"steps\": ${steps:-null}, \"dt\": ${K[dem.dt]},"
    echo "  \"particles\": ${natoms:-null}, \"wall_time_s\": $wall, \"timeout_s\": $timeout_s,"
    echo "  \"steady\": $steady, \"monitor_drift\": $drift, \"steady_tol\": $steady_tol,"
    echo "  \"dumps\": $dumps,"
    echo "  \"status\": \"$st\", \"message\": \"$(echo "$msg" | json_escape)\","
    echo "  \"finished\": \"$(date -u +%Y-%m-%dT%H:%M:%SZ)\""
    echo "}"
  } > "$dir/run.json.tmp" && mv "$dir/run.json.tmp" "$dir/run.json" ||
    { rm -f "$dir/run.json.tmp"; echo "$prog: $dir/run.json: cannot write" >&2; return 3; }
  if [ "$st" != ok ]; then
    echo "$prog: FAILED $scen $engine $size${tag:+ $tag}: $st: $msg (see $dir/screen.txt)" >&2
    [ "$st" = not_steady ] && return 6
    return 4
  fi
  echo "$prog: ok $scen $engine $size${tag:+ $tag}: $natoms particles, $steps steps, ${wall%.*} s"
  return 0
}

worst=0
for p in "${points[@]}"; do
  run_case "${p%%|*}" "${p#*|}"; r=$?
  # the first failure other than "not steady" wins over "not steady"
  if [ $r -ne 0 ] && { [ $worst -eq 0 ] || [ $worst -eq 6 ]; }; then worst=$r; fi
done
exit $worst
