#!/usr/bin/env bash
# One promise test of ekmcompare's inputs (tests/promises/compare.cmake):
#   case.sh CASE EKMCOMPARE SOURCE_DIR WORK_DIR
# Each CASE reproduces a way the promises were broken (issue 13) and checks
# the exit status, the one-line message and that no output was written and
# no input changed.
set -u
case_name=$1 ekmc=$2 src=$3 work=$4
fix=$src/tests/compare/fixtures
res=$src/results/chute/theta22
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1

fail() { echo "FAIL ($case_name): $*" >&2; exit 1; }

# run EXPECTED_RC NEEDLE -- CMD...: the status, and NEEDLE in the one line
# of stderr that starts with "ekmcompare: "
run() {
    local want=$1 needle=$2
    shift 3
    "$@" >out.txt 2>err.txt
    local rc=$?
    [ "$rc" = "$want" ] || fail "exit $rc, expected $want: $* ($(tail -n 3 err.txt))"
    local errs
    errs=$(grep -c '^ekmcompare: ' err.txt)
    if [ "$want" != 0 ]; then
        [ "$errs" = 1 ] || fail "expected one error line, got $errs: $(cat err.txt)"
    fi
    [ -z "$needle" ] || grep -qF -- "$needle" err.txt || fail "message '$(cat err.txt)' lacks '$needle'"
}

# an output that must not exist after a refused run
absent() { for f in "$@"; do [ ! -e "$f" ] || fail "output $f was written"; done; }

# the inputs, with checksums to show they are kept
keep() { md5sum "$@" >inputs.md5; }
kept() { md5sum --quiet -c inputs.md5 || fail "an input changed"; }

dump=$fix/liggghts_example.dump # 2 snapshots, radius column, no mass/time
cgopts=(--rho-p 2500 --dt 1e-5 --quiet)

case $case_name in
dump_negative_radius)
    # every radius of the first atom line -0.001: blamed --width before
    sed '10s/0.000482383 $/-0.001 /' "$dump" >a.dump
    run 2 "a.dump:10:142: radius: expected a positive finite number, got -0.001" -- \
        "$ekmc" cg a.dump -o a.h5 "${cgopts[@]}"
    absent a.h5 ;;
dump_all_radii_negative)
    sed 's/ \(0\.000[0-9]*\) $/ -\1 /' "$dump" >a.dump
    run 2 "a.dump:10:142: radius: expected a positive finite number, got -0.000482383" -- \
        "$ekmc" cg a.dump -o a.h5 "${cgopts[@]}"
    absent a.h5 ;;
dump_huge_radius)
    sed '10s/0.000482383 $/1e30 /' "$dump" >a.dump
    run 2 "a.dump:10:142: radius: expected a particle no larger than the box (longest edge 0.02 m), got 1e30" -- \
        "$ekmc" cg a.dump -o a.h5 "${cgopts[@]}"
    absent a.h5 ;;
dump_huge_box)
    # a box of +-1e300 along z: blamed --dz before
    sed 's/^0 0.02$/-1e300 1e300/' "$dump" >a.dump
    run 2 "a.dump:8: ITEM: BOX BOUNDS: z: expected a box the grid can hold" -- \
        "$ekmc" cg a.dump -o a.h5 "${cgopts[@]}"
    absent a.h5 ;;
dump_type_not_integer)
    # an atom type of 1.5 matched no --types and no --floor-type: the atom
    # silently left out (exit 0)
    sed '10s/^1 1 1 /1 1.5 1 /' "$dump" >a.dump
    run 2 "a.dump:10:3: type: expected an integer, got 1.5" -- \
        "$ekmc" cg a.dump -o a.h5 --types 1 "${cgopts[@]}"
    absent a.h5
    # base: every grain a floor grain (type 2) but the first, of type 1.5
    sed 's/^\([0-9]*\) 1 1 /\1 2 1 /' "$dump" | sed '10s/^1 2 1 /1 1.5 1 /' >b.dump
    run 2 "b.dump:10:3: type: expected an integer, got 1.5" -- "$ekmc" base b.dump -o b.h5
    absent b.h5 ;;
dump_box_infinite_length)
    sed 's/^-0.005 0.005$/-1e308 1e308/' "$dump" >a.dump
    run 2 "a.dump:6: ITEM: BOX BOUNDS: x: expected finite bounds lo < hi with a finite length" -- \
        "$ekmc" cg a.dump -o a.h5 "${cgopts[@]}"
    absent a.h5 ;;
dump_wide_particles)
    # particles so large that the kernel (width = their mean diameter) is
    # longer than the box: the dump's error, not --width's
    sed 's/ 0\.000[0-9]* $/ 0.004 /' "$dump" >a.dump
    run 2 "a.dump:9: the mean particle diameter 0.008 m (the kernel width: --width not given)" -- \
        "$ekmc" cg a.dump -o a.h5 "${cgopts[@]}"
    absent a.h5 ;;
gzip_corrupt_byte)
    # one byte changed inside the deflate data: was "a.dump.gz:0: truncated snapshot"
    cp "$fix/chute_liggghts_atoms.dump.gz" a.dump.gz
    printf '\x5a' | dd of=a.dump.gz bs=1 seek=100 conv=notrunc 2>/dev/null
    run 2 "a.dump.gz: corrupt gzip stream, detected at byte 102: invalid distances set" -- \
        "$ekmc" cg a.dump.gz -o a.h5 "${cgopts[@]}"
    absent a.h5 ;;
gzip_corrupt_check)
    # a byte changed that inflate takes: the CRC at the end tells
    cp "$fix/chute_liggghts_atoms.dump.gz" a.dump.gz
    printf '\x5a' | dd of=a.dump.gz bs=1 seek=60000 conv=notrunc 2>/dev/null
    run 2 "a.dump.gz: corrupt gzip stream, detected at byte 148222: incorrect data check" -- \
        "$ekmc" cg a.dump.gz -o a.h5 "${cgopts[@]}"
    absent a.h5 ;;
gzip_truncated_offset)
    # 100 bytes cut off: the first snapshot is used, the warning says where
    f=$fix/chute_liggghts_atoms.dump.gz
    head -c $(($(stat -c %s "$f") - 100)) "$f" >a.dump.gz
    "$ekmc" cg a.dump.gz -o a.h5 --rho-p 2500 --dt 1e-5 >out.txt 2>err.txt || fail "exit $?: $(cat err.txt)"
    grep -qF "warning: a.dump.gz: truncated gzip stream at byte 148126 (unexpected end of file)" err.txt ||
        fail "no truncation warning with the offset: $(cat err.txt)"
    grep -qF "1 of 1 snapshots" err.txt || fail "expected the one complete snapshot: $(cat err.txt)" ;;
cut_dump_expect_snapshots)
    # 100 bytes cut off a dump: a warning by default, an error with
    # --expect-snapshots (the campaign knows the frame count)
    f=$fix/chute_liggghts_atoms.dump.gz
    zcat "$f" >full.dump
    head -c $(($(stat -c %s full.dump) - 100)) full.dump >a.dump
    run 2 "truncated snapshot (last line cut short): expected 2 complete snapshots (--expect-snapshots)" -- \
        "$ekmc" cg a.dump -o a.h5 --expect-snapshots 2 "${cgopts[@]}"
    absent a.h5
    run 2 "full.dump: expected 3 snapshots (--expect-snapshots), got 2" -- \
        "$ekmc" cg full.dump -o a.h5 --expect-snapshots 3 "${cgopts[@]}"
    absent a.h5
    run 0 "" -- "$ekmc" cg full.dump -o a.h5 --expect-snapshots 2 "${cgopts[@]}"
    [ -s a.h5 ] || fail "no output with the expected count" ;;
dump_cut_inside_number)
    # a dump cut inside the last number of its last snapshot ("0.000468..."
    # cut to "0.0004680"), or only its final newline gone: what is left
    # parses, and the cut snapshot was used (2 of 2 snapshots). A last line
    # without its newline is cut short: skipped with the warning, an error
    # with --expect-snapshots; also read through a pipe
    head -c -4 "$dump" >a.dump
    head -c -1 "$dump" >b.dump
    for f in a.dump b.dump; do
        "$ekmc" cg $f -o a.h5 --rho-p 2500 --dt 1e-5 >out.txt 2>err.txt || fail "$f: exit $?: $(cat err.txt)"
        grep -qF "warning: $f:34: truncated snapshot (last line cut short): skipped, earlier snapshots kept" \
            err.txt || fail "$f: no truncation warning: $(cat err.txt)"
        grep -qF "1 of 1 snapshots" err.txt || fail "$f: expected the one complete snapshot: $(cat err.txt)"
        rm -f a.h5
        run 2 "$f:34: truncated snapshot (last line cut short): expected 2 complete snapshots (--expect-snapshots)" -- \
            "$ekmc" cg $f -o a.h5 --expect-snapshots 2 "${cgopts[@]}"
        absent a.h5
    done
    "$ekmc" cg <(head -c -4 "$dump") -o a.h5 --rho-p 2500 --dt 1e-5 >out.txt 2>err.txt ||
        fail "pipe: exit $?: $(cat err.txt)"
    grep -qF "1 of 1 snapshots" err.txt || fail "pipe: expected the one complete snapshot: $(cat err.txt)"
    [ -s a.h5 ] || fail "pipe: no output" ;;
dump_velocity_overflow)
    # a velocity of 1e300: exit 0, T, P and the SEs of every bin the atom
    # reaches inf or NaN in the output. The reader refuses a velocity
    # component of at least the speed of light at its line and column
    sed '10s/ -0.0203215 / 1e300 /' "$dump" >a.dump
    run 2 "a.dump:10:47: vx: expected a velocity component below the speed of light (|v| < 299792458 m/s), got 1e300" -- \
        "$ekmc" cg a.dump -o a.h5 --csv a.csv "${cgopts[@]}"
    absent a.h5 a.xdmf a.csv
    # below it, a mass of 1e295 kg (column 'mass') at 2e8 m/s still
    # overflows (m v^2, the SE of rho): the outputs refuse any inf, and NaN
    # where the bin holds particles (exit 4, naming the field, bin and time)
    sed 's/^ITEM: ATOMS id type type /ITEM: ATOMS id type mass /' "$dump" |
        sed '10s/^1 1 1 \(.*\) -0.0203215 /1 1 1e295 \1 2e8 /' >b.dump
    for out in "-o b.h5" "--csv b.csv" "--axes x,z -o b.h5" "--axes x,z --csv b.csv"; do
        # shellcheck disable=SC2086
        run 4 "b.dump: rho_se at " -- "$ekmc" cg b.dump $out "${cgopts[@]}"
        grep -qF "window t = 0.0025 s: expected a finite number, got inf" err.txt || fail "$out: $(cat err.txt)"
        absent b.h5 b.xdmf b.csv
    done ;;
dump_time_not_increasing)
    # ITEM: TIME going back (0, 0.01, 0.008) or repeating (0, 0.004, 0.004):
    # exit 0, and the output's t was not increasing. Times increase
    # strictly, within a file and across files; a step already read
    # (restart overlap) is still skipped
    tdump=$fix/lammps_time.dump # 3 snapshots, ITEM: TIME 0, 0.004, 0.008
    sed '23s/^0.004$/0.01/' "$tdump" >a.dump
    run 2 "a.dump:42: ITEM: TIME: expected a time after the previous snapshot's 0.01 s, got 0.008 s" -- \
        "$ekmc" cg a.dump -o a.h5 --every 1 "${cgopts[@]}"
    absent a.h5
    sed '42s/^0.008$/0.004/' "$tdump" >b.dump
    run 2 "b.dump:42: ITEM: TIME: expected a time after the previous snapshot's 0.004 s, got 0.004 s" -- \
        "$ekmc" cg b.dump --csv b.csv --every 1 "${cgopts[@]}"
    absent b.csv
    # the third snapshot in a second file, at 0.002 s
    sed -n '1,40p' "$tdump" >c1.dump
    sed -n '41,$p' "$tdump" | sed '2s/^0.008$/0.002/' >c2.dump
    run 2 "c2.dump:2: ITEM: TIME: expected a time after the previous snapshot's 0.004 s, got 0.002 s" -- \
        "$ekmc" cg c1.dump c2.dump -o c.h5 "${cgopts[@]}"
    absent c.h5
    # base selects by time: the same error
    sed 's/^ITEM: ATOMS id type mass radius vx /ITEM: ATOMS id type mass radius fz /; s/^\([0-9]*\) 1 /\1 2 /' \
        a.dump >p.dump
    run 2 "p.dump:42: ITEM: TIME: expected a time after the previous snapshot's 0.01 s, got 0.008 s" -- \
        "$ekmc" base p.dump -o p.h5 --from 0 --to 1
    absent p.h5
    # a restart overlap (snapshots 2 and 3 again in a second file): skipped
    sed -n '22,$p' "$tdump" >d2.dump
    "$ekmc" cg "$tdump" d2.dump -o d.h5 --rho-p 2500 >out.txt 2>err.txt || fail "overlap: exit $?: $(cat err.txt)"
    grep -qF "note: skipped 2 snapshots whose step was already read" err.txt || fail "overlap: $(cat err.txt)" ;;
score_shift_no_points)
    # --shift 1e300: exit 0 with 0 points and null everywhere before
    cp "$res/cg_lammps.h5" CG.h5 && cp "$res/ekm.h5" EKM.h5 && keep CG.h5 EKM.h5
    run 2 "score: --dem CG.h5 --ekm EKM.h5: field phi: no point in common (DEM coordinate 1e+300..1e+300 m with --shift 1e+300 m" -- \
        "$ekmc" score --dem CG.h5 --ekm EKM.h5 --shift 1e300 -o s.json
    absent s.json
    grep -q '|' out.txt && fail "a table was printed: $(cat out.txt)"
    kept ;;
score_swapped_files)
    cp "$res/cg_lammps.h5" CG.h5 && cp "$res/ekm.h5" EKM.h5 && keep CG.h5 EKM.h5
    run 2 "score: --dem EKM.h5: not an ekmcompare cg output (written by ekm run?)" -- \
        "$ekmc" score --dem EKM.h5 --ekm CG.h5 -o s.json
    absent s.json
    # a file of neither kind, as --ekm
    "$ekmc" cg "$dump" -o one.h5 "${cgopts[@]}" || fail "cg failed"
    /usr/bin/python3 -c "import h5py; f=h5py.File('one.h5','a'); del f.attrs['kernel']" || exit 77
    run 2 "score: --ekm one.h5: not an ekm run or ekmcompare cg output (expected the root attributes" -- \
        "$ekmc" score --dem CG.h5 --ekm one.h5 -o s.json
    absent s.json
    kept ;;
fit_rheology_ekm_file)
    cp "$res/ekm.h5" EKM.h5 && keep EKM.h5
    run 2 "fit: --rheology EKM.h5: not an ekmcompare cg output (written by ekm run?)" -- \
        "$ekmc" fit --rheology EKM.h5 --params T0 -o f.json
    absent f.json
    kept ;;
cg_output_is_dump)
    cp "$dump" d.dump && ln -s d.dump link.dump && ln d.dump hard.dump && keep d.dump
    for out in d.dump ./d.dump link.dump hard.dump; do
        run 3 "the output would overwrite the input d.dump" -- "$ekmc" cg d.dump -o "$out" "${cgopts[@]}"
        run 3 "the output would overwrite the input d.dump" -- "$ekmc" cg d.dump -o x.h5 --csv "$out" "${cgopts[@]}"
    done
    run 3 "x.h5: the output would overwrite the input ./x.h5" -- "$ekmc" cg d.dump -o ./x.h5 --csv x.h5 "${cgopts[@]}"
    absent x.h5
    kept ;;
cg_output_is_pair_dump)
    cp "$dump" d.dump && cp "$dump" p.dump && keep d.dump p.dump
    run 3 "p.dump: the output would overwrite the input p.dump" -- \
        "$ekmc" cg d.dump --pairs p.dump --pair-columns id1,id2,fx,fy,fz -o p.dump "${cgopts[@]}"
    kept ;;
score_output_is_input)
    cp "$res/cg_lammps.h5" CG.h5 && cp "$res/ekm.h5" EKM.h5 && keep CG.h5 EKM.h5
    run 3 "CG.h5: the output would overwrite the input CG.h5" -- "$ekmc" score --dem CG.h5 --ekm EKM.h5 -o CG.h5
    run 3 "./EKM.h5: the output would overwrite the input EKM.h5" -- "$ekmc" score --dem CG.h5 --ekm EKM.h5 -o ./EKM.h5
    kept ;;
fit_output_is_input)
    cp "$res/cg_lammps.h5" CG.h5 && cp "$src/scenarios/chute.ini" s.ini && keep CG.h5 s.ini
    run 3 "CG.h5: the output would overwrite the input CG.h5" -- "$ekmc" fit --rheology CG.h5 --params T0 -o CG.h5
    run 3 "CG.h5: the output would overwrite the input CG.h5" -- \
        "$ekmc" fit --rheology CG.h5 --params T0 -o f.json --ini CG.h5
    run 3 "s.ini: the output would overwrite the input s.ini" -- \
        "$ekmc" fit --rheology CG.h5 --params T0 --start s.ini -o s.ini
    run 3 "--ini ./f.json: the same file as -o f.json: expected two outputs" -- \
        "$ekmc" fit --rheology CG.h5 --params T0 -o f.json --ini ./f.json
    absent f.json
    kept ;;
fit_scenario_output_is_case_file)
    # -o naming a case's scenario replaced it with the fit's JSON (exit 0)
    cp "$res/cg_lammps.h5" CG.h5 && cp "$src/scenarios/chute.ini" s.ini
    echo '{"cases": [{"dem": "CG.h5", "scenario": "s.ini", "set": []}]}' >cases.json
    keep CG.h5 s.ini cases.json
    run 3 "s.ini: the output would overwrite the input s.ini" -- \
        timeout 60 "$ekmc" fit --scenario cases.json --params eta0 -o s.ini
    run 3 "s.ini: the output would overwrite the input s.ini" -- \
        timeout 60 "$ekmc" fit --scenario cases.json --params eta0 -o f.json --ini s.ini
    run 3 "CG.h5: the output would overwrite the input CG.h5" -- \
        timeout 60 "$ekmc" fit --scenario cases.json --params eta0 -o CG.h5
    run 3 "cases.json: the output would overwrite the input cases.json" -- \
        timeout 60 "$ekmc" fit --scenario cases.json --params eta0 -o cases.json
    run 3 "--ini f.json: the same file as -o f.json: expected two outputs" -- \
        timeout 60 "$ekmc" fit --scenario cases.json --params eta0 -o f.json --ini f.json
    absent f.json
    kept ;;
*)
    fail "unknown case" ;;
esac
echo "ok: $case_name"
