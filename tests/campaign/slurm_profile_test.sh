#!/usr/bin/env bash
# slurm_profile_test.sh: the shipped Slurm profile (workflow/profiles/slurm)
# submits what docs/campaign.md says, without a cluster.
#   slurm_profile_test.sh SOURCE_DIR BUILD_DIR WORK_DIR
# 1. `snakemake -n --profile workflow/profiles/slurm` (dry run, SIZE=ref,
#    NP=4): one cluster job (rule dem) per campaign scenario x supported
#    engine with ntasks = 4 and runtime = (points x [dem] timeout)/60 + 5
#    min from the resolved scenario; one cluster job (rule fit) per parameter
#    set (the training sets and their closure sets); every other rule is a localrule.
# 2. The same through a fake `sbatch` on PATH that records its arguments and
#    job script and refuses the job: each dem job is submitted with
#    --ntasks=4 and --time=<that runtime>, its job script runs that rule for
#    that scenario and engine with the campaign's config; Snakemake reports
#    the refused submissions and exits non-zero (--keep-going: all of them
#    are tried).
set -u
src=$1 build=$2 work=$3
command -v snakemake > /dev/null || { echo "snakemake not installed: skipped"; exit 77; }
ekm=$build/continuum/ekm
rm -rf "$work"; mkdir -p "$work/bin" "$work/submitted"
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
cd "$src" || exit 3
cfg=(--config size=ref np=4 "res=$work/res" "runs=$work/runs" "build=$build")

# the expected dem jobs: scenario engine runtime, from the resolved scenarios
expected=()
for ini in scenarios/*.ini; do
  s=$(basename "$ini" .ini)
  js=$("$ekm" scenario "$ini" --json) || { fail "ekm scenario $ini failed"; continue; }
  jq -e '[.keys | to_entries[] | select(.value.from != "default") | .key | split(".")[0]]
         | index("dem") != null and index("compare") != null' <<< "$js" > /dev/null || continue
  for e in liggghts lammps; do
    [ -r "dem_inputs/$e/$s.in" ] && [ ! -e "dem_inputs/$e/$s.unsupported" ] || continue
    js=$("$ekm" scenario "$ini" --engine "$e" --size ref --json) || { fail "ekm scenario $ini --engine $e failed"; continue; }
    min=$(jq -r '(.points | length) * (.keys["dem.timeout"].value | tonumber) / 60 | ceil + 5' <<< "$js")
    expected+=("$s $e $min")
  done
done
[ ${#expected[@]} -ge 4 ] || fail "only ${#expected[@]} dem jobs expected"

# 1. dry run
snakemake -n --profile workflow/profiles/slurm "${cfg[@]}" > "$work/dry.log" 2>&1 ||
  { tail -20 "$work/dry.log" >&2; fail "dry run failed"; }
n=$(grep -c '^rule dem:' "$work/dry.log")
[ "$n" -eq ${#expected[@]} ] || fail "dry run: $n cluster jobs of rule dem, expected ${#expected[@]}"
other=$(grep -E '^rule ' "$work/dry.log" | grep -v -E '^rule (dem|fit):' | sort -u | tr '\n' ' ')
[ -z "$other" ] || fail "dry run: rules other than dem and fit would go to the cluster: $other"
# the calibration fits are cluster jobs too (a scenario fit runs the EKM
# hundreds of times), one per parameter set (with the closure sets)
nfit=$(grep -c '^rule fit:' "$work/dry.log")
[ "$nfit" -eq 5 ] || fail "dry run: $nfit cluster jobs of rule fit, expected 5 (the sets chute, chute_mu_i, rheology, rheology_ekm_jam, rheology_mu_i)"
for r in cg ekm ekm_set score_ekm score_ekm_set score_engines; do
  grep -q "^localrule $r:" "$work/dry.log" || fail "dry run: no local job of rule $r"
done
for x in "${expected[@]}"; do
  set -- $x
  awk -v s="$1" -v e="$2" '/^rule dem:/ { j = 1 } j && /wildcards:/ { w = ($0 ~ "scenario=" s ", engine=" e "$") }
       j && /resources:/ { if (w) print; j = 0 }' "$work/dry.log" > "$work/res.txt"
  grep -q "ntasks=4, runtime=$3$" "$work/res.txt" ||
    fail "dry run: dem $1 $2: expected ntasks=4, runtime=$3, got '$(cat "$work/res.txt")'"
done

# 2. submission through a fake sbatch
cat > "$work/bin/sbatch" <<EOS
#!/bin/sh
# fake sbatch: records its arguments and job script, refuses the job
n=\$(ls "$work/submitted" | grep -c '^args')
printf '%s\n' "\$@" > "$work/submitted/args.\$n"
for a; do last=\$a; done
cp "\$last" "$work/submitted/script.\$n"
echo "sbatch: error: fake sbatch of the campaign test" >&2
exit 1
EOS
chmod +x "$work/bin/sbatch"
PATH=$work/bin:$PATH snakemake --profile workflow/profiles/slurm "${cfg[@]}" --until dem > "$work/submit.log" 2>&1 &&
  fail "refused submissions gave exit status 0"
grep -q "Error submitting jobscript" "$work/submit.log" || fail "the refused submission is not reported"
nsub=$(ls "$work/submitted" | grep -c '^args')
[ "$nsub" -eq ${#expected[@]} ] || fail "$nsub jobs submitted, expected ${#expected[@]}"
for x in "${expected[@]}"; do
  set -- $x
  a=$(grep -l -x -- "--job-name=ekmbench-dem-$1-$2" "$work"/submitted/args.* | head -n 1)
  [ -n "$a" ] || { fail "no sbatch call for dem $1 $2"; continue; }
  grep -q -x -- "--ntasks=4" "$a" || fail "dem $1 $2: sbatch without --ntasks=4: $(tr '\n' ' ' < "$a")"
  grep -q -x -- "--time=$3" "$a" || fail "dem $1 $2: sbatch without --time=$3: $(tr '\n' ' ' < "$a")"
  sc=${a/args/script}
  grep -q -- "--target-jobs 'dem:scenario=$1,engine=$2'" "$sc" || fail "dem $1 $2: job script does not run that job"
  grep -q -- "'size=ref' 'np=4'" "$sc" || fail "dem $1 $2: job script without the campaign's config"
done
[ -e "$work/runs" ] && [ -n "$(ls -A "$work/runs" 2> /dev/null | grep -v '^$')" ] &&
  find "$work/runs" -name run.json | grep -q . && fail "a DEM run happened locally"

[ $fails -eq 0 ] || { echo "$fails failure(s)" >&2; exit 1; }
echo "slurm_profile_test: all passed"
