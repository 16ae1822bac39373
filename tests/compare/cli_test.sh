#!/usr/bin/env bash
# cli_test.sh: the ekmcompare command line: outputs, exit codes, one-line
# errors naming file and line, and no output left behind on failure.
# usage: cli_test.sh EKMCOMPARE CG_SYNTH FIXTURES WORKDIR
set -u
ekmc=$1 synth=$2 fx=$3 work=$4
rm -rf "$work"; mkdir -p "$work"; cd "$work" || exit 1
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }

# expect CODE PATTERN -- command...: exit code, one stderr line matching PATTERN
expect() {
  local code=$1 pat=$2; shift 3
  "$@" > out.txt 2> err.txt; local rc=$?
  [ "$rc" -eq "$code" ] || fail "$*: exit $rc, expected $code ($(cat err.txt))"
  if [ "$code" -ne 0 ]; then
    [ "$(wc -l < err.txt)" -eq 1 ] || fail "$*: expected one error line, got: $(cat err.txt)"
    grep -qE -- "$pat" err.txt || fail "$*: message '$(cat err.txt)' does not match '$pat'"
  fi
}

expect 0 "" -- "$ekmc" --help
grep -q "Exit status" out.txt || fail "--help: no exit status section"
expect 0 "" -- "$ekmc" --version
expect 1 "unknown command 'frobnicate'" -- "$ekmc" frobnicate
# an option given last without its value is a usage error (it crashed: the
# value was read as NULL)
expect 1 "--axis: expected a value" -- "$ekmc" cg x.dump --axis
expect 1 "--shift: expected a value" -- "$ekmc" score --dem a.h5 --shift
expect 1 "--tol: expected a value" -- "$ekmc" steady m.txt --tol

# good inputs, every format
for f in liggghts_deck.dump lammps_time.dump lammps_time.dump.gz triclinic.dump; do
  expect 0 "" -- "$ekmc" cg "$fx/$f" --dt 1e-5 --rho-p 2500 --bins 8 -o "$f.h5" --quiet
  h5dump -H "$f.h5" > /dev/null || fail "$f.h5: h5dump cannot read it"
done
expect 0 "" -- "$ekmc" cg "$fx/liggghts_example.dump" --dt 1e-5 --rho-p 2500 -o ex.h5 --csv ex.csv --quiet
head -1 ex.csv | grep -q '^t,z,phi,phi_se,rho,rho_se,vx' || fail "ex.csv: bad header"
[ "$(wc -l < ex.csv)" -gt 10 ] || fail "ex.csv: too short"
# truncated: warning, exit 0, earlier snapshots kept
"$ekmc" cg "$fx/truncated.dump" -o trunc.h5 2> err.txt || fail "truncated.dump: non-zero exit"
grep -q "truncated.dump:[0-9]*: truncated snapshot" err.txt || fail "truncated.dump: no warning"
grep -q "2 of 2 snapshots" err.txt || fail "truncated.dump: expected 2 snapshots used"
# several files, a repeated step skipped, time series
"$synth" a.dump text 500 6 && "$synth" b.bin bin 500 6 || fail "cg_synth"
gzip -c a.dump > a.dump.gz
"$ekmc" cg a.dump a.dump.gz --every 2 -o series.h5 2> err.txt || fail "two files"
grep -q "skipped 6 snapshots" err.txt || fail "repeated steps not skipped: $(cat err.txt)"
h5dump -H -d phi series.h5 | grep -q "( 3, " || fail "--every 2 over 6 snapshots: expected 3 profiles"
expect 0 "" -- "$ekmc" cg b.bin --window 0.02 -o win.h5 --quiet
expect 0 "" -- "$ekmc" cg b.bin --steps 1000:3000 --kernel lucy -o steps.h5
grep -q "3 of 6 snapshots" err.txt || fail "--steps 1000:3000: expected 3 snapshots ($(cat err.txt))"
expect 0 "" -- "$ekmc" cg b.bin --axis x --kernel bins --bins 10 -o axis_x.h5 --quiet
h5dump -H -d x axis_x.h5 > /dev/null || fail "--axis x: no /x dataset"
h5dump -a axis axis_x.h5 | grep -q '"x"' || fail "--axis x: attribute axis"
expect 0 "" -- "$ekmc" cg b.bin --steady -o steady.h5
grep -q "steady window starts at\|using all of them" err.txt || fail "--steady: no note"
# score: a cg file against itself is a perfect score
expect 0 "" -- "$ekmc" score --dem series.h5 --ekm series.h5 -o score.json --quiet
grep -q "| phi | " out.txt || fail "score: no markdown table"
jq -e '.fields.phi.rel_l2 == 0' score.json > /dev/null || fail "score.json: rel_l2 of a file against itself"

# steady: the drift criterion gives, on the same file, what the awk of
# scripts/dem/run.sh gave (kept here as the oracle: mean of the last quarter
# of column 2 against the quarter before, %.4g, then "drift <= tol")
drift_awk() {
  awk '!/^#/ && NF>=2 {v[n++]=$2} END {
        if (n < 8) { print "null"; exit }
        q = int(n/4); a = 0; b = 0
        for (i = n-2*q; i < n-q; i++) a += v[i]
        for (i = n-q; i < n; i++) b += v[i]
        a /= q; b /= q; s = (a < 0 ? -a : a) + (b < 0 ? -b : b)
        if (s == 0) { print 0; exit }
        dd = (b - a) / (0.5 * s); printf "%.4g", (dd < 0 ? -dd : dd) }' "$1"
}
# n seed base trend noise tol: n samples base + trend i + noise (rand - 1/2)
for spec in "3 1 1 0 0.1 0.05" "7 2 1 0.01 0.1 0.05" "8 3 1 0 0.01 0.05" "9 4 2 0.001 0.5 0.1" \
            "10 5 -3 0.01 0.2 0.05" "11 6 1e-5 1e-8 1e-6 0.05" "50 7 0 0 0 0.05" "203 8 0.5 -0.002 0.3 0.2" \
            "1000 9 100 0.001 5 0.001" "64 10 0 0 1 0.5"; do
  set -- $spec
  awk -v n="$1" -v seed="$2" -v base="$3" -v trend="$4" -v noise="$5" 'BEGIN { srand(seed)
    print "# step value"
    for (i = 0; i < n; i++) { printf "%d %.17g\n", 100 * i, base + trend * i + noise * (rand() - 0.5)
      if (i % 7 == 3) print "# a comment line"; if (i % 11 == 5) print "" } }' > mon.txt
  want_d=$(drift_awk mon.txt) want_s=null
  if [ "$want_d" != null ]; then
    if awk "BEGIN { exit !($want_d <= $6) }"; then want_s=true; else want_s=false; fi
  fi
  want="{\"steady\": $want_s, \"drift\": $want_d, \"tol\": $6, \"samples\": $1}"
  got=$("$ekmc" steady mon.txt --tol "$6") || fail "steady ($spec): non-zero exit"
  [ "$got" = "$want" ] || fail "steady ($spec): got $got, expected $want"
done
# the verdict is on the printed drift: 0.0487804... prints as 0.04878 <= 0.04878
printf '0 9\n1 9\n2 9\n3 9\n4 1.0\n5 1.0\n6 1.05\n7 1.05\n' > mon.txt
expect 0 "" -- "$ekmc" steady mon.txt --tol 0.04878
grep -qx '{"steady": true, "drift": 0.04878, "tol": 0.04878, "samples": 8}' out.txt || fail "steady at the tolerance: $(cat out.txt)"
expect 0 "" -- "$ekmc" steady mon.txt --column 1
grep -qx '{"steady": false, "drift": 0.3636, "tol": 0.05, "samples": 8}' out.txt || fail "steady --column 1: $(cat out.txt)"
# a column a data line lacks is bad input naming file:line, not "0 samples"
expect 2 "mon.txt:[0-9]+: column 5: missing \(expected at least 5 columns, got 2\)" -- "$ekmc" steady mon.txt --column 5
printf '0 1\n1 x\n' > bad_mon.txt
expect 2 "bad_mon.txt:2: column 2: expected a finite number, got 'x'" -- "$ekmc" steady bad_mon.txt
expect 3 "nonexistent.txt: cannot open" -- "$ekmc" steady nonexistent.txt
expect 1 "steady: expected a monitor file" -- "$ekmc" steady
expect 1 "\-\-tol: expected a tolerance >= 0" -- "$ekmc" steady mon.txt --tol -1

# bad inputs: exit 2 (bad data) or 3 (a file that cannot be opened), one line
# file:line, no output file; a bad command line exits 1 (docs/exit-codes.md)
mk() { sed "$2" "$fx/lammps_time.dump" > "$1"; }
mk bad_num.dump '15s/^\([0-9]* 1\) [^ ]*/\1 1.2.3/'
mk bad_nan.dump '16s/^\([0-9]* 1 [^ ]* [^ ]*\) [^ ]*/\1 nan/'
mk bad_col.dump 's/ITEM: ATOMS id type mass radius vx vy vz z y x/ITEM: ATOMS id type mass radius vx vy vq z y x/'
mk bad_count.dump '0,/^8$/s/^8$/9/'
expect 2 "bad_num.dump:15:5: column 'mass': expected a number, got '1.2.3'" -- "$ekmc" cg bad_num.dump -o bad.h5
expect 2 "bad_nan.dump:16:35: column 'vx': expected a finite number, got 'nan'" -- "$ekmc" cg bad_nan.dump -o bad.h5
expect 2 "bad_col.dump:13: ITEM: ATOMS has no column 'vz'" -- "$ekmc" cg bad_col.dump -o bad.h5
expect 2 "bad_count.dump:22: expected 9 atoms \(ITEM: NUMBER OF ATOMS\), got 8" -- "$ekmc" cg bad_count.dump -o bad.h5
expect 3 "nonexistent.dump: cannot open" -- "$ekmc" cg nonexistent.dump -o bad.h5
# an output that cannot be written fails at once (before reading any dump: the
# dump named here does not exist), with nothing left behind
mkdir -p outdir
expect 3 "outdir/: cannot write the output: is a directory" -- "$ekmc" cg nonexistent.dump -o outdir/
expect 3 "outdir: cannot write the output: is a directory" -- "$ekmc" cg nonexistent.dump -o outdir
expect 3 "nodir/x.h5: cannot write the output: directory nodir: No such file" -- "$ekmc" cg nonexistent.dump -o nodir/x.h5
expect 3 "x.csv: cannot write the output: directory nodir" -- "$ekmc" cg nonexistent.dump --csv nodir/x.csv
[ -z "$(ls -A outdir)" ] || fail "cg -o outdir/: left $(ls outdir)"
expect 1 "has no ITEM: TIME: give --dt" -- "$ekmc" cg "$fx/liggghts_deck.dump" -o bad.h5
expect 1 "\-\-width: expected a positive width" -- "$ekmc" cg a.dump --width -1 -o bad.h5
expect 1 "\-\-kernel: expected gauss, lucy or bins, got 'box'" -- "$ekmc" cg a.dump --kernel box -o bad.h5
expect 1 "expected -o OUT.h5" -- "$ekmc" cg a.dump
expect 1 "unknown option '--bogus'" -- "$ekmc" cg a.dump --bogus -o bad.h5
expect 2 "no snapshots selected" -- "$ekmc" cg a.dump --from 99 -o bad.h5
expect 2 "expected an HDF5 file" -- "$ekmc" score --dem a.dump --ekm series.h5
mkdir -p adir.h5
expect 3 "adir.h5: cannot open: not a regular file" -- "$ekmc" score --dem adir.h5 --ekm series.h5
# pair dumps: a step missing from the pair dump; both contact-stress sources
zcat "$fx/chute_lammps_pairs.dump.gz" | sed 's/^30000$/30001/' > bad_pairs.dump
pc='c_pid[1],c_pid[2],c_pl[2],c_pl[3],c_pl[4]'
expect 2 "chute_lammps_atoms.dump.gz:[0-9]+: no pair-dump snapshot for step 30000 \(the next one is step 30001\)" -- \
  "$ekmc" cg "$fx/chute_lammps_atoms.dump.gz" --pairs bad_pairs.dump --pair-columns "$pc" -o bad.h5
expect 1 "expected --stress or --pairs, not both" -- \
  "$ekmc" cg "$fx/chute_lammps_atoms.dump.gz" --pairs "$fx/chute_lammps_pairs.dump.gz" --pair-columns "$pc" --stress c_sa -o bad.h5
expect 0 "" -- "$ekmc" cg "$fx/chute_lammps_atoms.dump.gz" --pairs "$fx/chute_lammps_pairs.dump.gz" --pair-columns "$pc" -o chute.h5 --quiet
h5dump -H -d mu chute.h5 > /dev/null || fail "chute.h5: no mu with pair-dump stress"
# --types 1: frozen base grains (type 2) are left out: the profile's solid
# volume per area is that of the type-1 grains (exact with the bins kernel)
expect 0 "" -- "$ekmc" cg "$fx/chute_lammps_atoms.dump.gz" --types 1 --kernel bins --csv types1.csv --quiet
expect 1 "\-\-types: expected comma-separated atom types" -- "$ekmc" cg a.dump --types 1,x -o bad.h5
sed 's/^ITEM: ATOMS id type /ITEM: ATOMS id kind /' "$fx/lammps_time.dump" > notype.dump
expect 2 "notype.dump:[0-9]+: ITEM: ATOMS has no column 'type' \(--types\)" -- "$ekmc" cg notype.dump --types 1 -o bad.h5
vdem=$(zcat "$fx/chute_lammps_atoms.dump.gz" | awk '
  /^ITEM: ATOMS/ { for (i = 3; i <= NF; i++) c[$i] = i - 2; a = 1; ns++; next }
  /^ITEM:/ { a = 0; next }
  a && $c["type"] == 1 { v += 4 / 3 * 3.141592653589793 * $c["radius"]^3 }
  END { printf "%.10g", v / ns / (0.016 * 0.012) }')
vcg=$(awk -F, 'NR > 1 { if (NR == 3) dz = $2 - z; z = $2; s[$1] += $3 }
  END { for (t in s) { tot += s[t]; n++ } printf "%.10g", tot / n * dz }' types1.csv)
awk -v a="$vdem" -v b="$vcg" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(a > 0 && d <= 1e-6 * a) }' ||
  fail "--types 1: solid volume per area $vcg, expected $vdem (type-1 grains)"
[ -e bad.h5 ] && fail "an output file was left behind by a failed run"
ls ./*.tmp.* > /dev/null 2>&1 && fail "temporary files left behind"
# an output that names an input is refused before any work (exit 3), and
# the input is left as it was
cp a.dump a_copy.dump
expect 3 "a.dump: the output would overwrite the input a.dump" -- "$ekmc" cg a.dump -o a.dump
expect 3 "\./a.dump: the output would overwrite the input a.dump" -- "$ekmc" cg a.dump --csv ./a.dump
expect 3 "series.h5: the output would overwrite the input series.h5" -- \
  "$ekmc" score --dem series.h5 --ekm series.h5 -o series.h5
cmp -s a.dump a_copy.dump || fail "a refused run changed its input"
h5dump -H series.h5 > /dev/null || fail "a refused score changed its input"
# a signal while writing (SIGXFSZ: the file-size limit is hit in the
# middle of the output) ends the run with 128+N and removes the temporary
rm -f big.csv
(ulimit -c 0; ulimit -f 8; exec "$ekmc" cg b.bin --every 1 --csv big.csv --quiet) 2> err.txt; rc=$?
[ "$rc" -eq $((128 + 25)) ] || fail "killed by SIGXFSZ: exit $rc, expected 153 ($(cat err.txt))"
[ -e big.csv ] && fail "killed by SIGXFSZ: big.csv left behind"
ls ./big.csv.tmp.* > /dev/null 2>&1 && fail "killed by SIGXFSZ: its temporary was left behind"

# an existing output is not touched by a failed run
cp series.h5 keep.h5
"$ekmc" cg bad_num.dump -o keep.h5 2>/dev/null
cmp -s series.h5 keep.h5 || fail "a failed run modified an existing output"

if [ "$fails" -gt 0 ]; then echo "$fails failure(s)" >&2; exit 1; fi
echo "cli_test: all passed"
