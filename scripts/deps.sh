#!/usr/bin/env bash
# Install the Debian packages ekmbench needs, and nothing when all are present.
# Package lists live in scripts/deps/*.txt (one package per line, # comments);
# each component (solver, DEM, comparison, figures) keeps its own list.
# Usage: scripts/deps.sh [LIST ...]   (default: every list)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
if [ $# -eq 0 ]; then
  lists=("$here"/deps/*.txt)
else
  lists=(); for l in "$@"; do lists+=("$here/deps/$l.txt"); done
fi
want=()
for f in "${lists[@]}"; do
  [ -r "$f" ] || { echo "deps.sh: no package list $f" >&2; exit 2; }
  while read -r pkg _; do
    case "$pkg" in ''|'#'*) continue ;; esac
    want+=("$pkg")
  done < "$f"
done
missing=()
for p in "${want[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "deps.sh: installing ${missing[*]}" >&2
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
