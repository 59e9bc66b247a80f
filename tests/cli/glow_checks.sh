#!/usr/bin/env bash
# glow_checks.sh TERRALUX WORKDIR
# An image sky with a sun in it (docs/lighting.md, "The sky's glow"): the bake's report states the
# glow's share of the sky's light as the rule splits it (computed here again from the image), says
# the probes sample it by rays of their own (their rays then pass the schedule's cap), and that
# with water they keep the whole sky instead; a uniform sky has no glow. With sun.follow_sky (the
# default) the glow is the sun instead (docs/lighting.md, "The image's sun"): the report states
# where it stands, its illuminance and its share, and the probes' sky has no glow left.
set -u
terralux=$1 work=$2
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }

# A 64 x 32 Radiance HDR: a sky of 1.0 and a 2 x 2-texel sun of 12 800, about 20 degrees up
# (flat RGBE scanlines).
python3 - "$work/sun.hdr" <<'PY'
import sys
w, h = 64, 32
with open(sys.argv[1], "wb") as f:
    f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w))
    for y in range(h):
        for x in range(w):
            f.write(bytes([200, 200, 200, 142]) if y in (12, 13) and x in (20, 21) else bytes([128, 128, 128, 129]))
PY

# The split, as Sky::splitGlow makes it: T <- 8 mean(min(Y, T)) from T = 8 mean(Y) until a step
# moves it by under 1 %, at least the luminance above which 1/16 of the sphere lies; the glow is
# what each texel has over T, its share over the whole sky's light (texels weighed by solid angle).
expected=$(python3 - <<'PY'
import math
def rgbe(m, e): return m * math.ldexp(1.0, e - 136)
w, h = 64, 32
Y = [[rgbe(200, 142) if y in (12, 13) and x in (20, 21) else rgbe(128, 129) for x in range(w)] for y in range(h)]
om = [2 * math.pi / w * (math.cos(math.pi * y / h) - math.cos(math.pi * (y + 1) / h)) for y in range(h)]
texels = [(Y[y][x], om[y]) for y in range(h) for x in range(w)]
flux = sum(v * o for v, o in texels)
T = 8 * flux / (4 * math.pi)
for _ in range(32):
    n = 8 * sum(min(v, T) * o for v, o in texels) / (4 * math.pi)
    settled, T = n > 0.99 * T, n
    if settled:
        break
covered = 0.0
for v, o in sorted(texels, reverse=True):
    covered += o
    if covered > 4 * math.pi / 16:
        T = max(T, v)
        break
# The glow as a sun (Sky::glowSun): its flux-weighted mean direction, and the radius of a disc of
# its spread about it, r = sqrt(2 E[angle^2 + texel solid angle / 6]).
def centre(x, y):
    t, p = math.pi * (y + 0.5) / h, ((x + 0.5) / w - 0.5) * 2 * math.pi
    return (math.sin(t) * math.sin(p), math.cos(t), -math.sin(t) * math.cos(p))
glow = [((Y[y][x] - T) * om[y], centre(x, y), om[y]) for y in range(h) for x in range(w) if Y[y][x] > T]
m = [sum(g * d[i] for g, d, _ in glow) for i in range(3)]
n = math.sqrt(sum(c * c for c in m))
s = [c / n for c in m]
spread = sum(g * (math.acos(min(1.0, sum(a * b for a, b in zip(d, s)))) ** 2 + o / 6) for g, d, o in glow)
radius = math.degrees(math.sqrt(2 * spread / sum(g for g, _, _ in glow)))
print(sum(max(v - T, 0.0) * o for v, o in texels) / flux, flux, radius)
PY
)
read -r expected flux radius <<<"$expected"

# report DIR SHARE SAMPLED: the report's sky_glow, and the rays that follow from it.
report() {
  python3 - "$1/bake_report.json" "$2" "$3" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
share, sampled = float(sys.argv[2]), sys.argv[3] == "true"
g = r["sky_glow"]
errors = []
if abs(g["share"] - share) > 1e-5 * max(1.0, share):
    errors.append(f"sky_glow.share {g['share']} != {share}")
if g["probes_sample_it"] != sampled:
    errors.append(f"sky_glow.probes_sample_it {g['probes_sample_it']} != {sampled}")
v = r["volumes"][0]
most, cap = v["rays_per_probe"]["max"], v["ray_schedule"]["max"]
# The glow's own rays come on top of the lattice's, which the schedule caps.
if sampled and not most > cap:
    errors.append(f"rays_per_probe.max {most} is not past ray_schedule.max {cap} with the glow sampled")
if not sampled and most > cap:
    errors.append(f"rays_per_probe.max {most} is past ray_schedule.max {cap} without the glow sampled")
if errors:
    print("FAIL: " + "; ".join(errors))
    sys.exit(1)
PY
}

common=(--bake --quiet --set probe_volumes[0].grid_dims=4,4 --set bake.quality=draft)
"$terralux" "${common[@]}" --set sky.mode=hdr --set sky.hdr="$work/sun.hdr" --set sun.follow_sky=false --out "$work/sun" ||
  fail "the bake under the sun sky exited $?"
report "$work/sun" "$expected" true || fail "under the sun sky"
# Not followed, a sun that outshines the rest of the image is worth a warning that names the setting.
grep -q "sun.follow_sky: false under sky.hdr, whose image has a sun (azimuth -61.9°" "$work/sun/bake_report.json" ||
  fail "no warning that the image's sun is baked into the probes"

python3 -c "import sys; sys.exit(0 if 0.9 < float(sys.argv[1]) < 1.0 else 1)" "$expected" ||
  fail "the sky's glow share $expected: the sun should hold nearly all of its light"

"$terralux" "${common[@]}" --set sky.mode=hdr --set sky.hdr="$work/sun.hdr" --set sun.follow_sky=false --set water.enabled=true --set water.level=700 \
  --out "$work/wet" || fail "the bake with water exited $?"
report "$work/wet" "$expected" false || fail "with water"

"$terralux" "${common[@]}" --set sky.mode=uniform --out "$work/uniform" || fail "the uniform bake exited $?"
report "$work/uniform" 0 false || fail "under a uniform sky"
# The glow as the sun: the 2 x 2 texels' centres stand at azimuth -61.9 degrees (u = 21/64) and
# 16.9 degrees up (v = 13/32); its illuminance is the glow's flux (their cosines to the mean
# direction are over 0.997), at 3e-5 scene units per lux.
"$terralux" --bake --set probe_volumes[0].grid_dims=4,4 --set bake.quality=draft --set sky.mode=hdr --set sky.hdr="$work/sun.hdr" \
  --out "$work/lit" > "$work/lit.txt" || fail "the bake with the image's sun exited $?"
report "$work/lit" 0 false || fail "with the image's sun"
! grep -q "sun.follow_sky: false" "$work/lit/bake_report.json" || fail "the followed image's sun is warned about"
python3 - "$work/lit/bake_report.json" "$expected" "$flux" "$radius" <<'PY' || fail "the image's sun in the report"
import json, sys
sun = json.load(open(sys.argv[1]))["sun"]
share, flux, radius = float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
errors = []
if abs(sun["angular_radius_deg"] - radius) > 1e-3: errors.append(f"angular_radius_deg {sun['angular_radius_deg']} != {radius}")
if sun.get("from_sky_image") is not True: errors.append("from_sky_image is not true")
if abs(sun["share_of_sky"] - share) > 1e-5: errors.append(f"share_of_sky {sun['share_of_sky']} != {share}")
if abs(sun["azimuth_deg"] + 61.875) > 0.5: errors.append(f"azimuth_deg {sun['azimuth_deg']} is not -61.9")
if abs(sun["elevation_deg"] - 16.875) > 0.5: errors.append(f"elevation_deg {sun['elevation_deg']} is not 16.9")
lux = share * flux / 3e-5
if not 0.997 * lux < sun["illuminance_lux"] <= 1.0001 * lux: errors.append(f"illuminance_lux {sun['illuminance_lux']} is not {lux}")
if errors:
    print("FAIL: " + "; ".join(errors)); sys.exit(1)
PY
grep -q "sun: the sky image's own (sun.follow_sky) at azimuth -61.9°, elevation 16.[89]°" "$work/lit.txt" ||
  fail "the summary does not say where the image's sun stands: $(grep 'sun:' "$work/lit.txt")"
# A scenario's image sky is held to the same rule, named by its path: not followed, it is warned
# about; followed, it is not.
cat > "$work/scenarios.terralux.json" <<JSON
{"probe_volumes": [{"grid_dims": [4, 4]}], "bake": {"quality": "draft", "error_map_resolution": 0},
 "scenarios": [{"name": "whole", "sky": {"mode": "hdr", "hdr": "$work/sun.hdr"}, "sun": {"follow_sky": false}},
               {"name": "lit", "sky": {"mode": "hdr", "hdr": "$work/sun.hdr"}}]}
JSON
"$terralux" --bake "$work/scenarios.terralux.json" --out "$work/scenarios" > "$work/scenarios.txt" 2>/dev/null ||
  fail "the bake with scenarios exited $?"
grep -q "scenarios\[0\].sun.follow_sky: false under scenarios\[0\].sky.hdr, whose image has a sun" "$work/scenarios/bake_report.json" ||
  fail "no warning that scenario 'whole' bakes the image's sun into its probes"
! grep -q "scenarios\[1\].sun.follow_sky" "$work/scenarios/bake_report.json" || fail "the followed scenario is warned about"
# Each scenario reports the sun it lit with: the followed image's sun, as the default's would be.
python3 - "$work/scenarios/bake_report.json" <<'PY' || fail "the scenarios' suns in the report"
import json, sys
r = json.load(open(sys.argv[1]))
errors = []
if "sun" in r: errors.append("the default scenario, a uniform sky with a sun set by its angles, reports a sun")
whole, lit = r["scenarios"]
if "sun" in whole: errors.append("scenario 'whole' (not following its image) reports an image's sun")
sun = lit.get("sun", {})
if sun.get("from_sky_image") is not True: errors.append("scenario 'lit' reports no sun from its sky image")
elif abs(sun["azimuth_deg"] + 61.875) > 0.5 or abs(sun["elevation_deg"] - 16.875) > 0.5 or sun["illuminance_lux"] <= 0:
    errors.append(f"scenario 'lit' reports its sun at {sun['azimuth_deg']}, {sun['elevation_deg']}, {sun['illuminance_lux']} lx")
if errors:
    print("FAIL: " + "; ".join(errors)); sys.exit(1)
PY
grep -q "scenario 'lit': .*, the sky image's sun at azimuth -61.9°, elevation 16.[89]°, [0-9]* lx" "$work/scenarios.txt" ||
  fail "the summary does not say where scenario 'lit's image sun stands: $(grep "scenario 'lit'" "$work/scenarios.txt")"
echo "sky glow share $expected as reported; sampled without water, not with it; none under a uniform sky; lit as the sun with sun.follow_sky"

