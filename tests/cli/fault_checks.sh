#!/usr/bin/env bash
# fault_checks.sh CASE TERRALUX WORKDIR
# Bakes that fail, die or collide: the earlier outputs survive byte for byte (docs/formats.md,
# "Staged and atomic writes").
#   inject      every file operation of a bake fails in turn (TERRALUX_FAIL_FILE_OP)
#   kill        kill -9 during a bake; the next bake removes what it left
#   concurrent  a second bake into a folder being written is refused; a dead bake's lock is not
set -u
case_=$1 terralux=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }
out=$work/out
# A small bake that writes every kind of file: probes and sidecar, reflection/, the scene, the report.
small=(--quiet --quality draft --set 'probe_volumes[0].grid_dims=2,2' --set bake.error_map_resolution=0
       --set reflection_probes.enabled=true --set reflection_probes.grid_dims=2,2
       --set reflection_probes.resolution=8 --set reflection_probes.ray_count=1)
# The same with other light, so that every file it writes differs.
changed=("${small[@]}" --set sun.elevation_deg=20)
long=(--quality reference --set 'probe_volumes[0].grid_dims=64,64')

# Checksums of every file below $1, by relative path.
sums() { (cd "$1" && find . -type f -print0 | sort -z | xargs -0 -r sha256sum); }
# Staging folders, temporaries or a lock file left below $1.
leftovers() { find "$1" \( -name '.staging-*' -o -name '*.tmp-*' -o -name '.terralux*' \) -print; }
# Waits until the background bake $1 reports progress into $2: it holds the folder's lock (taken
# before any work) and its work has begun.
await_bake() {
  for _ in $(seq 600); do
    grep -q "%\]" "$2" 2>/dev/null && return 0
    kill -0 "$1" 2>/dev/null || fail "the long bake ended early: $(cat "$2")"
    sleep 0.1
  done
  kill -9 "$1"
  fail "the long bake did not start its work"
}

"$terralux" --bake --out "$out" "${small[@]}" >/dev/null 2>"$work/stderr" || fail "first bake exited $?: $(cat "$work/stderr")"
[ -s "$out/reflection/probes.rprobe" ] && [ -s "$out/scene.bin" ] || fail "the first bake lacks files"
sums "$out" >"$work/before"

case "$case_" in
  inject)
    # How many file operations the changed bake does over these outputs, counted on a copy.
    cp -a "$out" "$work/count"
    TERRALUX_COUNT_FILE_OPS=1 "$terralux" --bake --out "$work/count" "${changed[@]}" >/dev/null 2>"$work/stderr" ||
      fail "counting bake exited $?: $(cat "$work/stderr")"
    line=$(grep "^terralux: [0-9]* file operations" "$work/stderr") || fail "no count: $(cat "$work/stderr")"
    ops=$(echo "$line" | cut -d' ' -f2)
    echo "$line"
    for kind in write fsync rename link; do
      echo "$line" | grep -q "[(,] *$kind [1-9]" || fail "no $kind operation counted: $line"
    done
    # The files that depend on the light differ, so that an unchanged file proves a rollback.
    for f in sh_coeffs/probes.shprobe reflection/probes.rprobe scene.gltf bake_report.json; do
      cmp -s "$out/$f" "$work/count/$f" && fail "the changed bake left $f as it was"
    done
    for n in $(seq "$ops"); do
      TERRALUX_FAIL_FILE_OP=$n "$terralux" --bake --out "$out" "${changed[@]}" >/dev/null 2>"$work/stderr"
      rc=$?
      [ $rc -eq 3 ] || fail "operation $n: exit $rc, expected 3: $(cat "$work/stderr")"
      [ "$(wc -l <"$work/stderr")" -eq 1 ] || fail "operation $n: not one line: $(cat "$work/stderr")"
      case "$(cat "$work/stderr")" in
        "terralux: $out: "* | "terralux: $out/"*": "*) ;;
        *) fail "operation $n: the message names no path in the output folder: $(cat "$work/stderr")" ;;
      esac
      sums "$out" | cmp -s - "$work/before" || fail "operation $n ($(cat "$work/stderr")) changed the earlier outputs"
      [ -z "$(leftovers "$out")" ] || fail "operation $n left $(leftovers "$out")"
    done
    # One past the last operation fails nothing: the count covered every operation.
    TERRALUX_FAIL_FILE_OP=$((ops + 1)) "$terralux" --bake --out "$out" "${changed[@]}" >/dev/null 2>"$work/stderr" ||
      fail "operation $((ops + 1)) failed: $(cat "$work/stderr")"
    for f in sh_coeffs/probes.shprobe reflection/probes.rprobe scene.bin; do
      cmp -s "$out/$f" "$work/count/$f" || fail "$f differs from the counted bake's"
    done
    ;;
  kill)
    "$terralux" --bake --out "$out" "${long[@]}" >/dev/null 2>"$work/stderr" &
    pid=$!
    await_bake "$pid" "$work/stderr"
    kill -9 "$pid"
    wait "$pid"
    rc=$?
    [ $rc -eq 137 ] || fail "the killed bake exited $rc"
    (cd "$out" && sha256sum --quiet -c "$work/before") || fail "the killed bake changed the earlier outputs"
    # The lock was on the folder itself: the killed bake left no lock file in the export.
    [ -z "$(find "$out" -name '.terralux*')" ] || fail "the killed bake left $(find "$out" -name '.terralux*')"
    # What a bake killed while writing leaves (the kill above lands before its export), and a
    # live process's staging folder, which the next bake must keep.
    mkdir "$out/.staging-$pid-0-00000000deadbeef" "$out/.staging-$$-0-00000000feedface"
    echo partial >"$out/.staging-$pid-0-00000000deadbeef/scene.gltf"
    echo partial >"$out/scene.gltf.tmp-$pid-0"
    echo partial >"$out/sh_coeffs/probes.shprobe.tmp-$pid-0123456789abcdef"
    "$terralux" --bake --out "$out" "${changed[@]}" >/dev/null 2>"$work/stderr" ||
      fail "the bake after the kill exited $?: $(cat "$work/stderr")"
    [ "$(leftovers "$out")" = "$out/.staging-$$-0-00000000feedface" ] ||
      fail "left behind: $(leftovers "$out")"
    sums "$out" | cmp -s - "$work/before" && fail "the bake after the kill wrote nothing"
    ;;
  concurrent)
    "$terralux" --bake --out "$out" "${long[@]}" >/dev/null 2>"$work/stderr" &
    pid=$!
    await_bake "$pid" "$work/stderr"
    "$terralux" --bake --out "$out" "${changed[@]}" >/dev/null 2>"$work/second"
    rc=$?
    [ $rc -eq 3 ] || { kill -9 "$pid"; fail "the second bake exited $rc, expected 3: $(cat "$work/second")"; }
    expected="terralux: $out: another bake is writing here (pid $pid); wait for it or choose another --out"
    [ "$(cat "$work/second")" = "$expected" ] || { kill -9 "$pid"; fail "message: $(cat "$work/second")"; }
    kill -0 "$pid" 2>/dev/null || fail "the first bake did not outlive the second"
    kill -9 "$pid"
    wait "$pid"
    (cd "$out" && sha256sum --quiet -c "$work/before") || fail "the earlier outputs changed"
    "$terralux" --bake --out "$out" "${changed[@]}" >/dev/null 2>"$work/stderr" ||
      fail "the bake after the holder died exited $?: $(cat "$work/stderr")"
    [ -z "$(leftovers "$out")" ] || fail "left behind: $(leftovers "$out")"
    sums "$out" | cmp -s - "$work/before" && fail "the third bake wrote nothing"
    ;;
  *) echo "unknown case $case_"; exit 2 ;;
esac
echo "ok: $case_"
