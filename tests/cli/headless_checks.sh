#!/usr/bin/env bash
# headless_checks.sh TERRALUX TERRALUX_BAKE WORKDIR CHECK_HEADLESS_CMAKE
# terralux-bake writes the same probes and scene as terralux --bake, and the headless rule
# (app/CheckHeadless.cmake) passes terralux-bake and refuses terralux, naming what it loads.
set -u
terralux=$1 bake=$2 work=$3 rule=$4
fail() { echo "FAIL: $*"; exit 1; }
rm -rf "$work" && mkdir -p "$work"
"$terralux" --bake --quiet --threads 2 --set bake.quality=draft --out "$work/terralux" >/dev/null || fail "terralux --bake"
"$bake" --bake --quiet --threads 2 --set bake.quality=draft --out "$work/bake" >/dev/null || fail "terralux-bake --bake"
n=0
for f in $(cd "$work/terralux" && find . -name '*.shprobe' -o -name 'scene.bin' -o -name '*.probes.json'); do
  cmp -s "$work/terralux/$f" "$work/bake/$f" || fail "$f differs between terralux and terralux-bake"
  n=$((n + 1))
done
[ "$n" -ge 3 ] || fail "only $n files compared"
echo "ok: $n files identical"
cmake -DBINARY="$bake" -P "$rule" >/dev/null 2>&1 || fail "the headless rule refuses terralux-bake: $(cmake -DBINARY="$bake" -P "$rule" 2>&1)"
out=$(cmake -DBINARY="$terralux" -P "$rule" 2>&1) && fail "the headless rule passes terralux, which loads Vulkan and Qt GUI"
grep -q "libvulkan.so" <<<"$out" && grep -q "libQt6Gui.so" <<<"$out" || fail "the rule's refusal does not name what terralux loads: $out"
echo "ok: the headless rule passes terralux-bake and refuses terralux"
