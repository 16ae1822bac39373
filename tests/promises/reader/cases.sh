#!/usr/bin/env bash
# The scenario reader's promises (issue 13): each case reproduces a way a
# scenario file or --set was once misread (silently, with a misattributed
# message, or by hanging) and checks that it is now refused with one error
# line naming the file, line (or --set) and key, the exit code of
# docs/exit-codes.md, and no output.
# usage: cases.sh CASE EKM_BINARY SOURCE_DIR WORK_DIR
set -u
case_name=$1 ekm=$2 src=$3 work=$4
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
chute=$src/scenarios/chute.ini

# line FILE REGEX: the number of the first line of FILE matching REGEX
line() { grep -an -m1 -E -- "$2" "$1" | cut -d: -f1; }

# expect EXIT 'PATTERN' ARGS...: ekm ARGS (at most 20 s) exits EXIT with
# exactly one stderr line matching PATTERN (grep -E), and writes no out.h5,
# out.xdmf or a temporary of them.
expect() {
    local want=$1 pattern=$2
    shift 2
    timeout 20 "$ekm" "$@" > stdout.txt 2> err.txt < /dev/null
    local rc=$?
    local lines
    lines=$(wc -l < err.txt)
    if [ "$rc" -ne "$want" ] || [ "$lines" -ne 1 ] || ! grep -qE -- "$pattern" err.txt ||
        ls out.h5 out.xdmf out.h5.tmp* out.xdmf.tmp* > /dev/null 2>&1; then
        echo "FAIL $case_name: ekm $*"
        echo "  exit $rc (want $want; 124: did not end in 20 s), $lines stderr line(s):"
        head -c 600 err.txt | sed 's/^/  | /'
        echo "  want one line matching: $pattern"
        ls out.* 2> /dev/null | sed 's/^/  left: /'
        exit 1
    fi
    echo "ok   $case_name: $(cat err.txt)"
}

run_args=(-o out.h5 --quiet --set run.t_end=1e-3)

case $case_name in
# --- no_silent_values: what the user wrote is read as written, or refused
duplicate_key)
    # rho_p given twice in [material]: the second one used to win
    sed 's/^rho_p .*/&\nrho_p = 2600/' "$chute" > dup.ini
    first=$(line dup.ini '^rho_p ') second=$((first + 1))
    expect 2 "^ekm: dup.ini:$second: \[material\] rho_p: duplicate key \(first at line $first\)$" \
        scenario dup.ini --json
    ;;
duplicate_tool_key)
    # a [dem] key given twice
    sed 's/^\[dem\]/&\ndiameter = 1\ndiameter = 2/' "$chute" > dup.ini
    first=$(line dup.ini '^diameter = 1') second=$((first + 1))
    expect 2 "^ekm: dup.ini:$second: \[dem\] diameter: duplicate key \(first at line $first\)$" \
        scenario dup.ini --json
    ;;
duplicate_section)
    # a second [run]: its keys used to replace the first's
    { cat "$chute"; printf '[run]\nt_end = 5\n'; } > dup.ini
    first=$(line dup.ini '^\[run\]') second=$(grep -c '' "$chute")
    second=$((second + 1))
    expect 2 "^ekm: dup.ini:$second: \[run\]: duplicate section \(first at line $first\)$" \
        run dup.ini "${run_args[@]}"
    ;;
hex_number)
    # 0x640 was strtod's 1600
    sed 's/^rho_p .*/rho_p = 0x640/' "$chute" > hex.ini
    expect 2 "^ekm: hex.ini:$(line hex.ini '^rho_p'): \[material\] rho_p: expected a number, got '0x640'$" \
        scenario hex.ini --json
    ;;
nul_in_value)
    # 16<NUL>00 was read as 16 (inih stops a line at a NUL)
    sed 's/^rho_p .*/rho_p = 16\x0000/' "$chute" > nul.ini
    n=$(line nul.ini '^rho_p')
    expect 2 "^ekm: nul.ini:$n:11: a NUL byte: expected text" scenario nul.ini --json
    ;;
set_number_syntax)
    # --set values: a blank before the number and hex were accepted (strtod)
    expect 2 "^ekm: --set material.rho_p: \[material\] rho_p: expected a number, got ' 2500'$" \
        scenario "$chute" --set "material.rho_p= 2500" --json
    expect 2 "^ekm: --set material.rho_p: \[material\] rho_p: expected a number, got '0x9C4'$" \
        scenario "$chute" --set "material.rho_p=0x9C4" --json
    ;;
set_integer_syntax)
    # an integer key (cells): a blank before the digits was accepted (strtol)
    expect 2 "^ekm: --set domain.cells: \[domain\] cells: expected an integer, got ' 60'$" \
        scenario "$chute" --set "domain.cells= 60" --json
    ;;
output_dt_zero)
    # output_dt = 0 silently meant t_end / 100 while -1 was refused
    expect 2 "^ekm: --set run.output_dt: \[run\] output_dt: expected a time > 0 \[s\], got 0$" \
        run "$chute" "${run_args[@]}" --set run.output_dt=0
    sed 's/^output_dt .*/output_dt = 0/' "$chute" > zero.ini
    expect 2 "^ekm: zero.ini:$(line zero.ini '^output_dt'): \[run\] output_dt: expected a time > 0" \
        run zero.ini "${run_args[@]}"
    ;;
indented_continuation)
    # an indented line after a key was inih's continuation: it replaced the value
    sed 's/^description .*/&\n    more text/' "$chute" > cont.ini
    expect 2 "^ekm: cont.ini:$(($(line cont.ini '^description') + 1)): expected '\[section\]' or 'key = value'$" \
        scenario cont.ini --json
    ;;
# --- no_hang: every run ends, or is refused before it starts
output_dt_tiny)
    # output_dt = 1e-300 wrote frames without end
    expect 2 "^ekm: --set run.output_dt: \[run\] output_dt: expected a time >= t_end / 99999 .*at most 100000 output frames.*got 1e-300$" \
        run "$chute" "${run_args[@]}" --set run.output_dt=1e-300
    ;;
fifo_scenario)
    # a FIFO: fopen waited for a writer forever
    mkfifo fifo.ini || exit 1
    expect 3 "^ekm: fifo.ini: cannot read scenario file: not a regular file$" run fifo.ini "${run_args[@]}"
    ;;
fifo_material)
    mkfifo fifo.ini || exit 1
    expect 3 "^ekm: fifo.ini: cannot read material file: not a regular file$" \
        run "$chute" --material fifo.ini "${run_args[@]}"
    ;;
dev_zero_scenario)
    expect 3 "^ekm: /dev/zero: cannot read scenario file: not a regular file$" run /dev/zero "${run_args[@]}"
    ;;
dev_urandom_scenario)
    expect 3 "^ekm: /dev/urandom: cannot read scenario file: not a regular file$" \
        run /dev/urandom "${run_args[@]}"
    ;;
directory_scenario)
    mkdir dir.ini
    expect 3 "^ekm: dir.ini: cannot read scenario file: not a regular file$" run dir.ini "${run_args[@]}"
    ;;
huge_scenario)
    # a scenario file larger than the documented 1 MiB (here: comments)
    { cat "$chute"; yes '; a comment line of the kind that makes a scenario file grow' | head -c 1100000; } \
        > huge.ini
    expect 3 "^ekm: huge.ini: cannot read scenario file: [0-9]+ bytes, more than the 1048576 a scenario may have$" \
        run huge.ini "${run_args[@]}"
    ;;
# --- clear_errors: the line at fault is the line named
unterminated_header)
    # "[domain" used to be blamed on a later key: "[model] length: unknown key"
    sed 's/^\[domain\]/[domain/' "$chute" > hdr.ini
    expect 2 "^ekm: hdr.ini:$(line hdr.ini '^\[domain'): malformed section header \"\[domain\" \(expected \[name\]\)$" \
        run hdr.ini "${run_args[@]}"
    ;;
nul_in_header)
    sed 's/^\[domain\]/[dom\x00ain]/' "$chute" > hdr.ini
    expect 2 "^ekm: hdr.ini:$(line hdr.ini '^\[dom'):5: a NUL byte: expected text" run hdr.ini "${run_args[@]}"
    ;;
long_header)
    # a 302-character header line
    sed "s/^\[domain\]/[domain$(printf 'x%.0s' $(seq 294))]/" "$chute" > hdr.ini
    expect 2 "^ekm: hdr.ini:$(line hdr.ini '^\[domainx'): line longer than 198 characters$" run hdr.ini "${run_args[@]}"
    ;;
set_value_with_newline)
    # a newline in a --set value was echoed into a two-line message
    expect 2 "^ekm: --set number 1: control character 0x0a at character 17: expected section.key=value" \
        scenario "$chute" --set "material.rho_p=1
2" --json
    ;;
material_file_check_line)
    # --material FIT.ini: a value check named FIT.ini without the line
    awk '/^\[/{p = ($0 ~ /^\[material\]/)} p' "$chute" | sed 's/^rho_p .*/rho_p = -0/' > fit.ini
    expect 2 "^ekm: fit.ini:$(line fit.ini '^rho_p'): \[material\] rho_p: expected a positive number, got -0$" \
        run "$chute" --material fit.ini "${run_args[@]}"
    ;;
cross_key_dt_max)
    # dt_max below dt_min's default: blamed dt_min, which the file does not give, with no line
    sed 's/^dt_max .*/dt_max = 1e-13/' "$src/scenarios/cooling.ini" > dt.ini
    expect 2 "^ekm: dt.ini:$(line dt.ini '^dt_max'): \[numerics\] dt_max: expected a time > dt_min = 1e-12 s, got 1e-13$" \
        scenario dt.ini --json
    ;;
cross_key_phi_loose)
    # phi_co below [hypo] phi_loose's default 0.1: blamed phi_loose (not given) with no line
    sed -e 's/^phi_co .*/phi_co = 0.05/' "$chute" > loose.ini
    expect 2 "^ekm: loose.ini:$(line loose.ini '^phi_co'): \[material\] phi_co: expected a number >= \[hypo\] phi_loose = 0.1" \
        scenario loose.ini --json
    ;;
inflow_missing_key)
    # type = inflow without phi: "FILE: [top] phi: expected ..., got 0", no line
    sed 's/^type = free/type = inflow/' "$chute" > inflow.ini
    expect 2 "^ekm: inflow.ini:$(line inflow.ini '^type = inflow'): \[top\] phi: missing \(required with type = inflow\)$" \
        scenario inflow.ini --json
    ;;
derived_default)
    # a sweep list's default derived from another key was blamed on "default:"
    sed 's/^phi *=.*/phi = 0/' "$src/scenarios/simple_shear.ini" > phi0.ini
    expect 2 "^ekm: phi0.ini:$(line phi0.ini '^phi *='): \[dem\] phis: expected volume fractions in \(0, phi_cp = 0.64\), got '0' \(the default: \[initial\] phi\)$" \
        scenario phi0.ini --json
    expect 2 "^ekm: --set top.velocity: \[dem\] rates: expected shear rates > 0 \[1/s\], got '0' \(the default: " \
        scenario "$src/scenarios/simple_shear.ini" --set top.velocity=-0.1 --json
    ;;
*)
    echo "cases.sh: unknown case '$case_name'" >&2
    exit 1
    ;;
esac
