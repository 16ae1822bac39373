#!/usr/bin/env bash
# monitor_stats.sh: mean and block-averaged standard error of every column
# of a run's monitor.txt over its last FRACTION (default 0.5) of rows.
#
#   scripts/dem/monitor_stats.sh [-w FRACTION] [-n NBLOCKS] DIR
#
# The standard error uses NBLOCKS (default 5) contiguous blocks, since
# successive rows are correlated. Column names come from the '# TimeStep'
# header line.
set -euo pipefail
frac=0.5; nb=5
while getopts "w:n:" o; do case $o in w) frac=$OPTARG ;; n) nb=$OPTARG ;; *) exit 1 ;; esac; done
shift $((OPTIND - 1))
[ $# -eq 1 ] || { echo "usage: monitor_stats.sh [-w FRACTION] [-n NBLOCKS] DIR" >&2; exit 1; }
[ -r "$1/monitor.txt" ] || { echo "monitor_stats: $1/monitor.txt: missing (a DEM run folder)" >&2; exit 3; }
awk -v frac="$frac" -v nb="$nb" '
/^# TimeStep/ { for (i = 3; i <= NF; i++) name[i - 1] = $i; nc = NF - 2; next }
/^#/ { next }
NF >= 2 { n++; for (i = 2; i <= NF; i++) x[n, i] = $i; nc = NF - 1 }
END {
  s = int(n * (1 - frac)) + 1; m = n - s + 1; bl = int(m / nb)
  if (bl < 1) { print "monitor_stats: " FILENAME ": too few rows" > "/dev/stderr"; exit 2 }
  for (i = 2; i <= nc + 1; i++) {
    t = 0; for (k = s; k <= n; k++) t += x[k, i]; mean = t / m
    sb = 0; sbb = 0
    for (b = 0; b < nb; b++) { bt = 0; for (k = s + b * bl; k < s + (b + 1) * bl; k++) bt += x[k, i]; bt /= bl; sb += bt; sbb += bt * bt }
    bm = sb / nb; var = (sbb / nb - bm * bm) * nb / (nb - 1); if (var < 0) var = 0
    printf "%-10s %12.5g +- %.2g\n", (name[i] != "" ? name[i] : "col" i), mean, sqrt(var / nb)
  }
}' "$1/monitor.txt"
