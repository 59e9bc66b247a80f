#!/usr/bin/env bash
# The bake's progress on stderr (what every other test turns off with --quiet): printed from the
# bake's worker threads, each line whole, the percentages never going back within a phase and
# ending at 100 %. Usage: progress_checks.sh TERRALUX OUTDIR
set -uo pipefail
terralux=$1 out=$2
rm -rf "$out"
"$terralux" --bake --quality draft --threads 4 --set bake.error_map_resolution=16 --out "$out" \
  >"$out.stdout" 2>"$out.stderr" || { echo "FAIL: bake exited $?"; cat "$out.stderr"; exit 1; }
lines=$(wc -l <"$out.stderr")
[ "$lines" -ge 5 ] || { echo "FAIL: only $lines progress lines"; cat "$out.stderr"; exit 1; }
line_re="^\\[ *[0-9]{1,3}%\\] [a-z][a-z' _0-9-]*[a-z'] \\([0-9]+\\.[0-9] s(, ETA [0-9]+ s)?\\)\$"
bad=$(grep -Ev "$line_re" "$out.stderr" | head -n 3)
[ -z "$bad" ] || { echo "FAIL: malformed progress lines:"; echo "$bad"; exit 1; }
tail -n 1 "$out.stderr" | grep -q '^\[100%\]' || { echo "FAIL: does not end at 100 %"; tail -n 3 "$out.stderr"; exit 1; }
# Within one phase the percentage only grows.
awk '{ p = substr($0, 2, 3) + 0; phase = $0; sub(/^\[[ 0-9]*%\] /, "", phase); sub(/ \(.*$/, "", phase);
       if (phase == last && p < lastp) { print "FAIL: " $0 " after " lastp "%"; exit 1 } last = phase; lastp = p }' \
  "$out.stderr" || exit 1
rm -rf "$out" "$out.stdout" "$out.stderr"
echo "progress: $lines lines"
