#!/usr/bin/env bash
# format_check.sh SRC: every C source and header of the project is formatted
# as .clang-format says (clang-format --dry-run --Werror lists any file that
# `make format` would change). Exit 77 (skipped) when clang-format is missing.
set -uo pipefail
src=${1:?usage: format_check.sh SRC}
command -v clang-format > /dev/null || { echo "format_check: clang-format not installed (scripts/deps.sh base)"; exit 77; }
cd "$src" || exit 2
mapfile -t files < <(git ls-files '*.c' '*.h' 2>/dev/null || find common continuum compare tests bench fuzz -name '*.[ch]')
[ ${#files[@]} -gt 0 ] || { echo "format_check: no C files found under $src"; exit 1; }
bad=0
for f in "${files[@]}"; do
  if ! clang-format --dry-run --Werror "$f" > /dev/null 2>&1; then
    echo "format_check: $f is not formatted (run: make format)"; bad=1
  fi
done
[ $bad -eq 0 ] && echo "format_check: ${#files[@]} files formatted as .clang-format says"
exit $bad
