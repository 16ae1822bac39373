# ini.awk: print the value of one key of one section of an INI file.
# Usage: awk -v sec=dem -v key=smoke.steps -f ini.awk FILE
# Comments start with ';' or '#' (whole line or after the value); keys and
# values are trimmed. Prints nothing and exits 1 when the key is absent.
BEGIN { found = 0 }
{
  line = $0
  sub(/[;#].*$/, "", line)
  gsub(/^[ \t\r]+|[ \t\r]+$/, "", line)
  if (line == "") next
  if (line ~ /^\[.*\]$/) { cur = substr(line, 2, length(line) - 2); next }
  if (cur != sec) next
  eq = index(line, "="); if (eq == 0) next
  k = substr(line, 1, eq - 1); v = substr(line, eq + 1)
  gsub(/^[ \t]+|[ \t]+$/, "", k); gsub(/^[ \t]+|[ \t]+$/, "", v)
  if (k == key) { val = v; found = 1 }
}
END { if (found) { print val; exit 0 } exit 1 }
