#!/usr/bin/env bash
# render_checks.sh TERRALUX WORKDIR: renders the sample (baking first), a debug view as EXR, and
# checks the files are the requested images. Skips (77) when no Vulkan device exists.
set -u
terralux=$1 work=$2
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
"$terralux" --render --out beauty.png --size 320x180 --quiet >stdout 2>stderr
rc=$?
if [ $rc -eq 3 ] && grep -q "no Vulkan" stderr; then echo "SKIP: $(cat stderr)"; exit 77; fi
[ $rc -eq 0 ] || fail "render exited $rc: $(cat stderr)"
grep -q "view 0 beauty, 1 probe volume" stdout || fail "unexpected report: $(cat stdout)"
# The metered exposure is printed, follows the light (four times the sun and sky: +2 EV) and is
# not printed for a manual camera.
ev() { sed -n 's/^exposure: EV100 \([0-9.-]*\) metered (histogram), compensation 0.0 EV$/\1/p' "$1"; }
a=$(ev stdout)
[ -n "$a" ] || fail "no metered exposure in the report: $(cat stdout)"
"$terralux" --render --out bright.png --size 320x180 --quiet --set sun.illuminance=400000 --set sky.intensity=4 >stdout2 \
  || fail "bright render exited $?"
b=$(ev stdout2)
awk -v a="$a" -v b="$b" 'BEGIN { d = b - a; exit !(d > 1.9 && d < 2.1) }' \
  || fail "four times the light metered $a -> $b EV100, expected +2"
"$terralux" --render --out manual.png --size 64x48 --quiet --set camera.exposure_mode=manual >stdout2 \
  || fail "manual render exited $?"
grep -q "^exposure:" stdout2 && fail "a manual camera printed a metered exposure: $(cat stdout2)"
[ -f bake/sh_coeffs/probes.shprobe ] || fail "render did not bake first"
head -c 8 beauty.png | od -An -tx1 | grep -q "89 50 4e 47" || fail "beauty.png is not a PNG"
"$terralux" --render --out irr.exr --size 64x64 --debug-view 50 --quiet >stdout || fail "EXR render"
head -c 4 irr.exr | od -An -tx1 | grep -q "76 2f 31 01" || fail "irr.exr is not OpenEXR"
# Views 54 and 56 read the diagnostics the bake wrote beside the .shprobe.
[ -s bake/sh_coeffs/probes.probes.json ] || fail "no probes.probes.json beside the .shprobe"
"$terralux" --render --out err.png --size 64x64 --debug-view interpolation-error --overlay probes,leaves \
  --quiet >stdout 2>stderr || fail "view 56 render exited $?"
grep -q "view 56 interpolation-error" stdout || fail "unexpected report: $(cat stdout)"
[ -s stderr ] && fail "view 56 warned: $(cat stderr)"
# A sidecar of another bake: the render still works and says which file and why.
printf '{"format": "terralux-probe-diagnostics", "version": 1, "probe_count": 3}' >bake/sh_coeffs/probes.probes.json
"$terralux" --render --out err.png --size 64x64 --debug-view 56 --quiet >stdout 2>stderr || fail "stale sidecar render exited $?"
grep -q "^terralux: warning: .*probes.probes.json: probe_count 3 does not match the .shprobe's 64 probes" stderr \
  || fail "no warning for a stale sidecar: $(cat stderr)"
"$terralux" --render --out beauty.png --size 64x64 --quiet >stdout 2>stderr || fail "beauty with a stale sidecar"
[ -s stderr ] && fail "beauty warned about the sidecar: $(cat stderr)"
"$terralux" --render --out x.png --overlay probes,grid --quiet >stdout 2>stderr
[ $? -eq 2 ] || fail "--overlay grid accepted"
grep -q "^terralux: --overlay probes,grid: 'grid' is not one of probes, leaves$" stderr || fail "overlay message: $(cat stderr)"
# A bake without a map: view 56 says why it is grey.
"$terralux" --bake --quiet --quality draft --out nomap --set bake.error_map_resolution=0 >/dev/null || fail "bake without a map"
"$terralux" --render --out nomap.png --size 32x32 --debug-view 56 --set export.out_dir="$work/nomap" \
  --set bake.quality=draft --set bake.error_map_resolution=0 --quiet >stdout 2>stderr \
  || fail "view 56 without a map exited $?"
grep -q "^terralux: note: this bake measured no interpolation-error map (bake.error_map_resolution = 0" stderr \
  || fail "no note for a bake without a map: $(cat stderr)"
# A DEM past the mesh's vertex budget (a committed crop resampled to 2400 x 2400, over the budget
# of 2^22 vertices): the line says the drawn grid keeps every 2nd row and column, and from near
# the ground the patches that need it are drawn from the DEM's own vertices, within the pixel.
dems=$(cd "$(dirname "$0")/../data/dem" && pwd)
gdal_translate -q -outsize 2400 2400 -r cubic "$dems/rainier_crop.tif" big.tif || fail "gdal_translate"
"$terralux" --render --dem big.tif --out big.png --size 640x360 --no-probes --set ao.enabled=false \
  --camera 210,10,600 --quiet >stdout 2>stderr || fail "render of the large DEM exited $?: $(cat stderr)"
python3 - stdout <<'PY' || fail "large DEM: $(cat stdout)"
import re, sys
text = open(sys.argv[1]).read()
m = re.search(r"^terrain: (\d+) of the DEM's (\d+) triangles at the level of detail, within ([0-9.]+) px of it "
              r"\(drawn from every 2nd row and column; (\d+) patch\(es\) from the DEM's own vertices, (\d+) of them\)$",
              text, re.M)
if not m:
    sys.exit("no terrain line with the stride and the detail patches")
drawn, whole, px, patches, vertices = int(m[1]), int(m[2]), float(m[3]), int(m[4]), int(m[5])
if not (0 < drawn <= whole and px <= 1.0 and patches >= 1 and vertices >= patches * 9):
    sys.exit(f"drawn {drawn} of {whole}, {px} px, {patches} patches of {vertices} vertices")
PY
ls -a | grep -q "\.tmp-" && fail "temporary files left behind"
echo "ok: rendered"
