#!/usr/bin/env bash
# dump_record.sh: what a DEM run produced, and whether it is still there.
#
#   scripts/dem/dump_record.sh record DIR
#   scripts/dem/dump_record.sh verify DIR [NAME...]
#
# record prints the JSON object run.sh writes as "dumps" in DIR/run.json:
# one entry per dump file of the run (DIR/*.dump, DIR/*.dump.gz), {"NAME":
# {"frames": ITEM: TIMESTEP lines, "bytes": file size, "sha256": checksum}}.
# verify compares the dumps NAME... (default: every one run.json records)
# with that record and prints one line per dump that differs, naming it and
# what differs (frames, bytes, sha256: found and recorded), e.g.
#   dump_record.sh: runs/chute/lammps-smoke/atoms.dump: frames 7 (run.json:
#   17), bytes 51200 (run.json: 124416), sha256 1f2e... (run.json: 9a0b...):
#   the dump changed after the run
# A run.json without a "dumps" record (a run made before they were
# recorded) is not checked: one note line, exit 0.
# Exit status (docs/exit-codes.md): 0 every dump matches its record (or
# there is no record); 1 usage; 3 DIR/run.json or a recorded dump is
# missing or unreadable; 4 a dump differs from its record (the run's
# output is not what the run produced: a failed input); 7 no jq.
set -uo pipefail
prog=dump_record.sh
usage() { echo "$prog: usage: dump_record.sh record DIR | verify DIR [NAME...]" >&2; exit 1; }
[ $# -ge 2 ] || usage
mode=$1 dir=$2; shift 2
command -v jq > /dev/null || { echo "$prog: jq not installed (scripts/deps.sh base)" >&2; exit 7; }

# facts FILE: "FRAMES BYTES SHA256" of one dump (frames of the uncompressed
# text for a .gz); non-zero if the file cannot be read
facts() {
  local f=$1 frames bytes sum
  [ -f "$f" ] && [ -r "$f" ] || return 3
  bytes=$(stat -c %s -- "$f") || return 3
  sum=$(sha256sum -- "$f") || return 3
  sum=${sum%% *}
  if [[ $f == *.gz ]]; then
    frames=$(gzip -cd -- "$f" 2> /dev/null | grep -c '^ITEM: TIMESTEP')
  else
    frames=$(grep -c '^ITEM: TIMESTEP' -- "$f")
  fi
  echo "$frames $bytes $sum"
}

case $mode in
  record)
    [ $# -eq 0 ] || usage
    obj='{}'
    for f in "$dir"/*.dump "$dir"/*.dump.gz; do
      [ -e "$f" ] || continue
      read -r fr by sh < <(facts "$f") || { echo "$prog: $f: cannot read the dump" >&2; exit 3; }
      [ -n "${sh:-}" ] || { echo "$prog: $f: cannot read the dump" >&2; exit 3; }
      obj=$(jq -c --arg n "${f##*/}" --argjson fr "$fr" --argjson by "$by" --arg sh "$sh" \
        '. + {($n): {frames: $fr, bytes: $by, sha256: $sh}}' <<< "$obj")
    done
    echo "$obj" ;;
  verify)
    json=$dir/run.json
    [ -r "$json" ] || { echo "$prog: $json: no run.json (the DEM run did not finish)" >&2; exit 3; }
    rec=$(jq -c '.dumps // empty' "$json" 2> /dev/null) ||
      { echo "$prog: $json: not valid JSON" >&2; exit 3; }
    if [ -z "$rec" ]; then
      echo "$prog: note: $json records no dumps (a run made before they were recorded): not checked" >&2
      exit 0
    fi
    names=("$@")
    [ ${#names[@]} -gt 0 ] || mapfile -t names < <(jq -r 'keys[]' <<< "$rec")
    rc=0
    for n in "${names[@]}"; do
      want=$(jq -r --arg n "$n" '.[$n] | if . == null then empty else "\(.frames) \(.bytes) \(.sha256)" end' <<< "$rec")
      if [ -z "$want" ]; then
        echo "$prog: $json: records no dump $n (it has: $(jq -r 'keys | join(", ")' <<< "$rec"))" >&2
        [ $rc -ne 0 ] || rc=4; continue
      fi
      if [ ! -e "$dir/$n" ]; then
        echo "$prog: $dir/$n: missing, run.json records it (the dump was removed after the run)" >&2
        [ $rc -ne 0 ] || rc=3; continue
      fi
      got=$(facts "$dir/$n") || { echo "$prog: $dir/$n: cannot read the dump" >&2; [ $rc -ne 0 ] || rc=3; continue; }
      [ "$got" = "$want" ] && continue
      read -r gf gb gs <<< "$got"; read -r wf wb ws <<< "$want"
      what=()
      [ "$gf" = "$wf" ] || what+=("frames $gf (run.json: $wf)")
      [ "$gb" = "$wb" ] || what+=("bytes $gb (run.json: $wb)")
      [ "$gs" = "$ws" ] || what+=("sha256 ${gs:0:12}... (run.json: ${ws:0:12}...)")
      echo "$prog: $dir/$n: $(IFS=,; echo "${what[*]}" | sed 's/,/, /g'): the dump changed after the run" >&2
      [ $rc -ne 0 ] || rc=4
    done
    exit $rc ;;
  *) usage ;;
esac
