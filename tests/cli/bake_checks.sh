#!/usr/bin/env bash
# bake_checks.sh CASE TERRALUX CHECKER VALIDATOR WORKDIR BUILD_DIR [DEM]
# End-to-end bake cases that need more than one command.
set -u
case_=$1 terralux=$2 checker=$3 validator=$4 work=$5 build=$6 dem=${7:-}
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }
case "$case_" in
  sample)
    "$terralux" --bake --out "$work/out" --quiet >"$work/stdout" || fail "bake exited $?"
    grep -q "sh_coeffs/probes.shprobe" "$work/stdout" || fail "bake did not list what it wrote"
    "$checker" "$work/out" || fail "glTF entries disagree with the .shprobe headers"
    "$validator" "$work/out/scene.gltf" "$build"
    rc=$?; [ $rc -eq 0 ] || [ $rc -eq 77 ] || fail "glTF validator reported errors"
    [ $rc -eq 77 ] && exit 77
    ;;
  real)
    [ -f "$dem" ] || { echo "SKIP: shared DEM not present: $dem"; exit 77; }
    "$terralux" --bake --dem "$dem" --out "$work/out" --quality draft --quiet \
      --set 'probe_volumes[0].grid_dims=16,16' --set terrain.max_resolution=512 >/dev/null || fail "bake exited $?"
    "$checker" "$work/out" || fail "glTF entries disagree with the .shprobe headers"
    "$validator" "$work/out/scene.gltf" "$build"
    rc=$?; [ $rc -eq 0 ] || [ $rc -eq 77 ] || fail "glTF validator reported errors"
    ;;
  threads)
    "$terralux" --bake --out "$work/a" --quiet --threads 1 --quality draft >/dev/null || fail "1 thread"
    "$terralux" --bake --out "$work/b" --quiet --threads 2 --quality draft >/dev/null || fail "2 threads"
    cmp "$work/a/sh_coeffs/probes.shprobe" "$work/b/sh_coeffs/probes.shprobe" || fail ".shprobe differs"
    cmp "$work/a/scene.bin" "$work/b/scene.bin" || fail "scene.bin differs"
    ;;
  interrupt)
    "$terralux" --bake --out "$work/out" --quiet --quality draft >/dev/null || fail "first bake"
    before=$(cd "$work/out" && sha256sum sh_coeffs/probes.shprobe scene.gltf scene.bin bake_report.json)
    # A long bake, interrupted early: exit 130 and the earlier files unchanged.
    timeout --preserve-status -s INT 1 "$terralux" --bake --out "$work/out" --quiet --quality reference \
      --set 'probe_volumes[0].grid_dims=64,64' >/dev/null 2>"$work/stderr"
    rc=$?
    [ $rc -eq 130 ] || fail "interrupted bake exited $rc, expected 130"
    grep -q "interrupted; earlier outputs" "$work/stderr" || fail "no interruption message"
    after=$(cd "$work/out" && sha256sum sh_coeffs/probes.shprobe scene.gltf scene.bin bake_report.json)
    [ "$before" = "$after" ] || fail "earlier outputs changed"
    ls -a "$work/out" | grep -q "staging\|\.tmp-" && fail "temporary files left behind"
    ;;
  *) echo "unknown case $case_"; exit 2 ;;
esac
echo "ok: $case_"
