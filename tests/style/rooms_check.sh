#!/usr/bin/env bash
# rooms_check.sh: the folders ("rooms", README "What is here") include one
# another one way only.  Each tracked C file's #include "X.h" is resolved
# to the room (top folder) that holds X.h (its own room's first; a name
# held by several other rooms is an error), and a room may include only
# the rooms listed for it below (its own always):
#
#   common     -
#   law        common            (the constitutive law: pure functions)
#   scenario   law common        (the scenario service; the law's parameter structs)
#   continuum  scenario law common
#   compare    scenario common   (coarse-graining and scores: no EKM; of scenario/ only
#              cg_keys.h, the table of the cg options)
#   calibrate  compare continuum scenario law common
#              (of continuum/ only point.h: the EKM solved in-process at a
#              material, by the one steady policy; no solver internals)
#
# A room's main.c (its program's front) may also include the rooms listed
# in `front`: compare/main.c runs the calibration's `ekmcompare fit`.
#
# Then, over every room: no import circles between modules. A module is a
# file name without its extension (dir/x.c with dir/x.h; a private header
# dir/x_impl.h belongs to dir/x); module A uses module B when a file of A
# includes B's header (resolved in A's own folder first, then by its name
# anywhere). The uses must form no loop (tsort).
#
#   tests/style/rooms_check.sh SOURCE_DIR
#
# Exit status: 0 the rules hold; 1 a rule broken (one line per include on
# stderr: file:line, the header, its room); 2 usage; 77 (skipped) outside
# a git checkout.
set -uo pipefail
[ $# -eq 1 ] || { echo "usage: rooms_check.sh SOURCE_DIR" >&2; exit 2; }
cd "$1" || { echo "rooms_check.sh: $1: not a directory" >&2; exit 2; }
git rev-parse --git-dir > /dev/null 2>&1 || { echo "rooms_check.sh: $1: not a git checkout: skipped"; exit 77; }

declare -A allowed=([common]="" [law]="common" [scenario]="law common" [continuum]="scenario law common"
  [compare]="scenario common" [calibrate]="compare continuum scenario law common")
declare -A front=([compare]="calibrate")
# "ROOM>TARGET": the only headers of TARGET that ROOM may include
declare -A only=([calibrate > continuum]="point.h" [compare > scenario]="cg_keys.h")

# header name -> the rooms holding one of that name (the first path component)
declare -A rooms_of
while IFS= read -r h; do
  name=${h##*/}
  rooms_of[$name]="${rooms_of[$name]:-} ${h%%/*}"
done < <(git ls-files '*.h' | grep -v -E '^(tests|fuzz|bench)/')

bad=0
checked=0
for room in "${!allowed[@]}"; do
  while IFS= read -r f; do
    checked=$((checked + 1))
    while IFS=: read -r line header; do
      held=${rooms_of[$header]:-}
      [ -z "$held" ] && continue # a system header or a generated one
      case " $held " in *" $room "*) continue ;; esac # its own room's
      read -r -a holders <<< "$held"
      if [ "${#holders[@]}" -ne 1 ]; then
        echo "rooms_check.sh: $f:$line: \"$header\" is held by several rooms ($held): ambiguous" >&2
        bad=1
        continue
      fi
      target=${holders[0]}
      if [ -n "${only[$room > $target]+set}" ]; then
        case " ${only[$room > $target]} " in *" $header "*) continue ;; esac
        echo "rooms_check.sh: $f:$line: includes \"$header\" of $target/, which $room/ may not (of $target/ only: ${only[$room > $target]})" >&2
        bad=1
        continue
      fi
      case " ${allowed[$room]} " in *" $target "*) continue ;; esac
      if [ "${f##*/}" = main.c ]; then
        case " ${front[$room]:-} " in *" $target "*) continue ;; esac
      fi
      echo "rooms_check.sh: $f:$line: includes \"$header\" of $target/, which $room/ may not (it may: ${allowed[$room]:-nothing})" >&2
      bad=1
    done < <(grep -n -o -E '^#include "[^"]+"' "$f" | sed -E 's/#include "([^"]+)"/\1/; s#[^:]*/##2')
  done < <(git ls-files "$room/*.c" "$room/*.h")
done

# module graph: one "A B" line per use of module B by module A
declare -A header_path # header name -> its one path, "" when several
while IFS= read -r h; do
  name=${h##*/}
  if [ -n "${header_path[$name]+set}" ]; then header_path[$name]=""; else header_path[$name]=$h; fi
done < <(git ls-files '*.h' | grep -v -E '^(tests|fuzz|bench)/')
edges=$(mktemp)
trap 'rm -f "$edges"' EXIT
modules=0
while IFS= read -r f; do
  modules=$((modules + 1))
  dir=${f%/*}
  from=${f%.[ch]}
  from=${from%_impl}
  echo "$from $from" >> "$edges"
  while IFS= read -r header; do
    if [ -f "$dir/$header" ]; then
      target=$dir/$header
    else
      target=${header_path[${header##*/}]:-}
    fi
    [ -z "$target" ] && continue # a system or generated header, or ambiguous (above)
    to=${target%.h}
    to=${to%_impl}
    [ "$to" = "$from" ] || echo "$from $to" >> "$edges"
  done < <(grep -o -E '^#include "[^"]+"' "$f" | sed -E 's/#include "([^"]+)"/\1/')
done < <(git ls-files '*.c' '*.h' | grep -v -E '^(tests|fuzz|bench)/')
loop=$(tsort < "$edges" 2>&1 > /dev/null | grep -v 'input contains a loop' | sed 's/^tsort: /  /')
if [ -n "$loop" ]; then
  echo "rooms_check.sh: an import circle between modules (the modules of a loop, as tsort finds it):" >&2
  printf '%s\n' "$loop" >&2
  bad=1
fi

if [ "$bad" -ne 0 ]; then
  exit 1
fi
echo "rooms_check.sh: $checked files of ${!allowed[*]}: every include within its room's rules; $modules files of every room: no import circle"
