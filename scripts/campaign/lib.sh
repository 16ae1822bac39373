# lib.sh: shared by the campaign steps (sourced). Provides root, die, and
# cmpkey: a [compare] key of a scenario file looked up as
# <engine>.<size>.KEY, <size>.KEY, <engine>.KEY, KEY (like [dem]).
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
die() { echo "${prog:-campaign}: $*" >&2; exit 2; }
# cmpkey INI ENGINE SIZE KEY [DEFAULT]
cmpkey() {
  local ini=$1 engine=$2 size=$3 k=$4 cand v
  for cand in "$engine.$size.$k" "$size.$k" "$engine.$k" "$k"; do
    if v=$(awk -v sec=compare -v key="$cand" -f "$root/scripts/dem/ini.awk" "$ini"); then
      echo "$v"; return 0
    fi
  done
  if [ $# -ge 5 ]; then echo "$5"; return 0; fi
  echo "${prog:-campaign}: $ini: [compare] $k: missing key (also tried $size.$k, $engine.$k)" >&2
  return 2
}
# inikey INI SECTION KEY: a key of any section (empty and status 1 if absent)
inikey() { awk -v sec="$2" -v key="$3" -f "$root/scripts/dem/ini.awk" "$1"; }
# campaign_scenarios: the scenarios of the campaign, one name per line:
# every scenarios/*.ini with both a [dem] and a [compare] section
campaign_scenarios() {
  local ini
  for ini in "$root"/scenarios/*.ini; do
    grep -q '^\[dem\]' "$ini" && grep -q '^\[compare\]' "$ini" && basename "$ini" .ini
  done
  return 0
}
# engines that can run scenario S (no dem_inputs/<engine>/S.unsupported)
supported() { [ -r "$root/dem_inputs/$2/$1.in" ] && [ ! -e "$root/dem_inputs/$2/$1.unsupported" ]; }
