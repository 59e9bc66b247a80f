#!/usr/bin/env bash
# bake_checks.sh CASE TERRALUX CHECKER VALIDATOR WORKDIR BUILD_DIR [DEM]
# End-to-end bake cases that need more than one command.
set -u
case_=$1 terralux=$2 checker=$3 validator=$4 work=$5 build=$6 dem=${7:-}
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }
# same_outputs A B WHAT: the two bakes wrote the same files, each the same bytes but the report.
same_outputs() {
  (cd "$1" && find . -type f | sort) >"$work/a.list"
  (cd "$2" && find . -type f | sort) >"$work/b.list"
  cmp -s "$work/a.list" "$work/b.list" || fail "the two bakes wrote different files"
  while read -r f; do
    [ "$f" = "./bake_report.json" ] && continue
    cmp -s "$1/$f" "$2/$f" || fail "$f differs between $3"
  done <"$work/a.list"
}
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
    # Every file is the same byte for byte, except the report's timings and thread count.
    same_outputs "$work/a" "$work/b" "1 and 2 threads"
    untimed() { python3 -c '
import json, sys
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items() if k != "threads" and not k.endswith("time_s")}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v
print(json.dumps(strip(json.load(open(sys.argv[1]))), sort_keys=True))' "$1"; }
    [ "$(untimed "$work/a/bake_report.json")" = "$(untimed "$work/b/bake_report.json")" ] ||
      fail "bake_report.json differs beyond timings"
    grep -q "TimeSeconds\|time_s" "$work/a/scene.gltf" && fail "scene.gltf carries a timing"
    ;;
  kernels)
    # The x86-64-v3 build of the tracer and the baseline one give the same bake, byte for byte:
    # a farm of mixed CPUs gets the same tiles from every node.
    TERRALUX_TRACER_KERNEL=baseline "$terralux" --bake --out "$work/a" --quiet --quality draft >/dev/null ||
      fail "baseline bake exited $?"
    "$terralux" --bake --out "$work/b" --quiet --quality draft >/dev/null || fail "default bake exited $?"
    kernel() { python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["tracer_kernel"])' "$1"; }
    [ "$(kernel "$work/a/bake_report.json")" = baseline ] || fail "the pinned bake reports $(kernel "$work/a/bake_report.json")"
    v3=no
    if grep -qw avx2 /proc/cpuinfo && grep -qw fma /proc/cpuinfo && grep -qw bmi1 /proc/cpuinfo &&
       grep -qw bmi2 /proc/cpuinfo; then v3=yes; fi
    expected=baseline; [ $v3 = yes ] && expected=x86-64-v3
    [ "$(kernel "$work/b/bake_report.json")" = $expected ] ||
      fail "the default bake reports $(kernel "$work/b/bake_report.json"), expected $expected"
    [ $v3 = yes ] || { echo "SKIP: this CPU has no x86-64-v3, both bakes ran the baseline"; exit 77; }
    same_outputs "$work/a" "$work/b" "the baseline and x86-64-v3 kernels"
    ;;
  albedo_map)
    # An albedo map drapes a PNG texture over the exported terrain; dem is the fixtures' folder.
    "$terralux" --bake --dem "$dem/bigtujunga_utm11_crop.tif" --out "$work/out" --quality draft --quiet \
      --set terrain.albedo_mode=map --set terrain.albedo_map="$dem/albedo_utm11.tif" >/dev/null || fail "bake exited $?"
    python3 - "$work/out/scene.gltf" <<'PY' || fail "the glTF's albedo texture is not as expected"
import json, struct, sys, zlib, os
gltf = json.load(open(sys.argv[1]))
bin_ = open(os.path.join(os.path.dirname(sys.argv[1]), gltf["buffers"][0]["uri"]), "rb").read()
pbr = gltf["materials"][0]["pbrMetallicRoughness"]
assert pbr["baseColorTexture"]["index"] == 0, pbr
assert pbr["baseColorFactor"] == [1.0, 1.0, 1.0, 1.0], pbr
image = gltf["images"][gltf["textures"][0]["source"]]
assert image["mimeType"] == "image/png", image
view = gltf["bufferViews"][image["bufferView"]]
png = bin_[view.get("byteOffset", 0):view.get("byteOffset", 0) + view["byteLength"]]
assert png[:8] == b"\x89PNG\r\n\x1a\n", png[:8]
pos, idat, ihdr = 8, b"", None
while pos < len(png):
    n, kind = struct.unpack(">I4s", png[pos:pos + 8])
    data = png[pos + 8:pos + 8 + n]
    if kind == b"IHDR": ihdr = struct.unpack(">IIBBBBB", data)
    if kind == b"IDAT": idat += data
    pos += 12 + n
w, h, depth, colour = ihdr[:4]
# The map's 15 m over the crop's 2850 x 1890 m footprint, texel centres on its corners.
assert (w, h, depth, colour) == (191, 127, 8, 2), ihdr
assert len(zlib.decompress(idat)) == h * (1 + 3 * w), "the PNG does not decode to 191 x 127 RGB"
# TEXCOORD_0 puts the footprint's corners on the corner texels' centres.
uv = gltf["accessors"][gltf["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"]]
uvView = gltf["bufferViews"][uv["bufferView"]]
first = struct.unpack_from("<2f", bin_, uvView["byteOffset"])
last = struct.unpack_from("<2f", bin_, uvView["byteOffset"] + 8 * (uv["count"] - 1))
near = lambda a, b: abs(a - b) < 1e-6
assert near(first[0], 0.5 / w) and near(first[1], 0.5 / h), first
assert near(last[0], 1 - 0.5 / w) and near(last[1], 1 - 0.5 / h), last
PY
    "$validator" "$work/out/scene.gltf" "$build"
    rc=$?; [ $rc -eq 0 ] || [ $rc -eq 77 ] || fail "glTF validator reported errors"
    [ $rc -eq 77 ] && exit 77
    ;;
  replace)
    # A renamed volume and a scene switched off leave none of the earlier bake's files behind.
    "$terralux" --bake --out "$work/out" --quiet --quality draft >/dev/null || fail "first bake"
    echo mine >"$work/out/notes.txt"
    "$terralux" --bake --out "$work/out" --quiet --quality draft --set 'probe_volumes[0].name=valley' \
      --set export.gltf=false >/dev/null || fail "second bake"
    [ -e "$work/out/sh_coeffs/probes.shprobe" ] && fail "the renamed volume's old .shprobe stayed"
    [ -e "$work/out/sh_coeffs/probes.probes.json" ] && fail "the renamed volume's old sidecar stayed"
    [ -e "$work/out/scene.gltf" ] && fail "scene.gltf stayed with export.gltf off"
    [ -e "$work/out/scene.bin" ] && fail "scene.bin stayed with export.gltf off"
    [ -f "$work/out/sh_coeffs/valley.shprobe" ] || fail "no valley.shprobe"
    [ "$(cat "$work/out/notes.txt")" = mine ] || fail "a file the bake does not own was touched"
    python3 -c 'import json,sys; f=json.load(open(sys.argv[1]))["files"]; sys.exit(f != ["sh_coeffs/valley.shprobe", "sh_coeffs/valley.probes.json", "bake_report.json"])' \
      "$work/out/bake_report.json" || fail "the report does not list exactly the files written"
    ;;
  interrupt)
    "$terralux" --bake --out "$work/out" --quiet --quality draft >/dev/null || fail "first bake"
    before=$(cd "$work/out" && sha256sum sh_coeffs/probes.shprobe scene.gltf scene.bin bake_report.json)
    # A long bake, interrupted early: exit 130 and the earlier files unchanged.
    # The interrupt is sent once the bake reports progress (its handler is in place by then),
    # not after a fixed time that a loaded machine may not honour.
    "$terralux" --bake --out "$work/out" --quality reference \
      --set 'probe_volumes[0].grid_dims=64,64' >/dev/null 2>"$work/stderr" &
    pid=$!
    for _ in $(seq 300); do grep -q "%\]" "$work/stderr" 2>/dev/null && break; sleep 0.1; done
    kill -INT "$pid"
    wait "$pid"
    rc=$?
    [ $rc -eq 130 ] || fail "interrupted bake exited $rc, expected 130"
    grep -q "interrupted; earlier outputs" "$work/stderr" || fail "no interruption message"
    after=$(cd "$work/out" && sha256sum sh_coeffs/probes.shprobe scene.gltf scene.bin bake_report.json)
    [ "$before" = "$after" ] || fail "earlier outputs changed"
    ls -a "$work/out" | grep -q "staging\|\.tmp-" && fail "temporary files left behind"
    ;;
  reflection)
    # Reflection probes: the .rprobe and simvx records land beside the probes, 16 probes are
    # clamped to 8 records with a warning naming both counts, the glTF points at the files, the
    # bytes do not depend on the thread count, and switching them off removes the files.
    small=(--quality draft --set reflection_probes.enabled=true --set reflection_probes.resolution=8
           --set reflection_probes.ray_count=2 --set 'probe_volumes[0].grid_dims=4,4' --set bake.error_map_resolution=0)
    "$terralux" --bake --out "$work/a" --quiet --threads 1 "${small[@]}" >/dev/null 2>"$work/stderr" || fail "bake exited $?"
    grep -q "^terralux: warning: reflection_probes: 16 probes, the simvx box records hold 8: exported ids 0,1,2,3,4,5,6,7" \
      "$work/stderr" || fail "no clamp warning: $(cat "$work/stderr")"
    [ "$(stat -c %s "$work/a/reflection/probes.simvx.bin")" = 400 ] || fail "probes.simvx.bin is not 400 bytes"
    [ "$(stat -c %s "$work/a/reflection/probes.simvx.wire")" = 416 ] || fail "probes.simvx.wire is not 8 x 52 bytes"
    # 64-byte header, 16 probes of 104 bytes and a 8, 4 chain of RGB floats.
    [ "$(stat -c %s "$work/a/reflection/probes.rprobe")" = $((64 + 16 * (104 + 12 * 6 * (64 + 16)))) ] ||
      fail "probes.rprobe has the wrong size"
    python3 - "$work/a" <<'PY' || fail "the glTF or the report does not describe the reflection files"
import json, sys
out = sys.argv[1]
ext = json.load(open(out + "/scene.gltf"))["scenes"][0]["extensions"]["TERRALUX_lighting"]["reflection_probes"]
assert ext["uri"] == "reflection/probes.rprobe" and ext["probes"] == 16 and ext["simvx_probes"] == 8, ext
assert ext["simvx_ids"] == list(range(8)) and ext["encoding"] == "cubemap" and ext["mip_count"] == 2, ext
assert ext["enabled"] is True and ext["grid_dims"] == [4, 4], ext
report = json.load(open(out + "/bake_report.json"))
r = report["reflection_probes"]
assert r["simvx"]["exported_ids"] == list(range(8)) and r["simvx"]["probes"] == 16, r
assert "reflection/probes.simvx.wire" in report["files"], report["files"]
assert report["warnings"] and "16 probes" in report["warnings"][0], report["warnings"]
PY
    "$validator" "$work/a/scene.gltf" "$build"
    rc=$?; [ $rc -eq 0 ] || [ $rc -eq 77 ] || fail "glTF validator reported errors"
    "$terralux" --bake --out "$work/b" --quiet --threads 2 "${small[@]}" >/dev/null 2>&1 || fail "2-thread bake exited $?"
    for f in probes.rprobe probes.simvx.bin probes.simvx.wire; do
      cmp -s "$work/a/reflection/$f" "$work/b/reflection/$f" || fail "reflection/$f differs between 1 and 2 threads"
    done
    # A chosen subset, and the encoding that stores face colours only.
    "$terralux" --bake --out "$work/b" --quiet "${small[@]}" --set reflection_probes.simvx_subset=15,3 \
      --set reflection_probes.encoding=faces >/dev/null 2>"$work/stderr" || fail "subset bake exited $?"
    [ -s "$work/stderr" ] && fail "a chosen subset still warned: $(cat "$work/stderr")"
    [ "$(stat -c %s "$work/b/reflection/probes.simvx.wire")" = 104 ] || fail "the subset's wire is not 2 x 52 bytes"
    [ "$(stat -c %s "$work/b/reflection/probes.rprobe")" = $((64 + 16 * 104)) ] || fail "the faces file has the wrong size"
    "$terralux" --bake --out "$work/b" --quiet --quality draft >/dev/null || fail "bake without reflection probes"
    [ -e "$work/b/reflection/probes.rprobe" ] && fail "the earlier bake's reflection files stayed"
    grep -q reflection_probes "$work/b/scene.gltf" && fail "the glTF still names reflection probes"
    ;;
  reflection_error)
    # --compare-reference reports each encoding's error against the 16x reference.
    "$terralux" --bake --out "$work/out" --quiet --quality draft --compare-reference --set 'probe_volumes[0].grid_dims=2,2' \
      --set bake.error_map_resolution=0 --set reflection_probes.enabled=true --set reflection_probes.grid_dims=2,1 \
      --set reflection_probes.resolution=8 --set reflection_probes.ray_count=2 >"$work/stdout" || fail "bake exited $?"
    grep -q "error vs reference at roughness 0.25: faces mean" "$work/stdout" || fail "no error line: $(cat "$work/stdout")"
    python3 - "$work/out/bake_report.json" <<'PY' || fail "the report's reflection error is not as expected"
import json, sys
e = json.load(open(sys.argv[1]))["reflection_probes"]["reference_error"]
rows = e["by_roughness"]
assert [r["roughness"] for r in rows] == [0.25, 0.5, 0.75, 1.0], rows
assert e["reference_resolution"] == 32 and e["reference_rays"] == 2 * 6 * 32 * 32 * 2, e
for r in rows:
    for enc in ("faces", "cubemap"):
        s = r[enc]
        assert 0 <= s["mean"] <= s["p95"] <= s["max"], r
# Six face colours cannot follow a glossy reflection that a cube map can.
assert rows[0]["cubemap"]["mean"] < rows[0]["faces"]["mean"], rows[0]
PY
    ;;
  *) echo "unknown case $case_"; exit 2 ;;
esac
echo "ok: $case_"
