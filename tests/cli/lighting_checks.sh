#!/usr/bin/env bash
# lighting_checks.sh TERRALUX VALIDATOR WORKDIR BUILD_DIR
# A bake's scene.gltf carries the project's lighting in TERRALUX_lighting: its sky, shadows and fog
# sections are what --print-project prints with the same project and --set edits (plus the
# computed_* and resolved_* keys), the sun agrees with the project's, and the Khronos validator
# finds no error. Once on the embedded sample, once with a project file whose HDR sky is named
# relative to it (the extension keeps the path as written), once with a lake (its section and
# node; neither without water).
set -u
terralux=$1 validator=$2 work=$3 build=$4
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }

# check PROJECT_JSON SCENE_GLTF CASCADES [MEAN_SKY_R,G,B]
check() {
  python3 - "$@" <<'EOF'
import json, math, sys

project = json.load(open(sys.argv[1]))
doc = json.load(open(sys.argv[2]))
cascades = int(sys.argv[3])
mean_sky = [float(x) for x in sys.argv[4].split(",")] if len(sys.argv) > 4 else None
errors = []
def expect(ok, what):
    if not ok:
        errors.append(what)
def close(a, b, rel=1e-6):
    return abs(a - b) <= rel * max(1.0, abs(a), abs(b))

expect("TERRALUX_lighting" in doc.get("extensionsUsed", []), "TERRALUX_lighting not in extensionsUsed")
expect("TERRALUX_lighting" not in doc.get("extensionsRequired", []), "TERRALUX_lighting is required")
ext = (doc.get("scenes") or [{}])[0].get("extensions", {}).get("TERRALUX_lighting")
if ext is None:
    print("FAIL: no scenes[0].extensions.TERRALUX_lighting")
    sys.exit(1)

# The authored sections, less the keys the extension adds, are the printed project's.
for section in ("sky", "shadows", "fog"):
    authored = {k: v for k, v in ext[section].items()
                if not k.startswith("computed_") and not k.startswith("resolved_")}
    expect(authored == project[section],
           f"{section}: {json.dumps(authored, sort_keys=True)} != {json.dumps(project[section], sort_keys=True)}")
expect(ext["exposure_ev"] == project["camera"]["exposure_ev"], "exposure_ev differs")

sun, psun = ext["sun"], project["sun"]
for key in ("azimuth_deg", "elevation_deg", "illuminance"):
    expect(sun[key] == psun[key], f"sun.{key}: {sun[key]} != {psun[key]}")
expect(close(sun["angular_radius_deg"], psun["angular_radius_deg"]), "sun.angular_radius_deg differs")
expect(all(close(a, b) for a, b in zip(sun["color"], psun["color"])), "sun.color differs")
if psun["mode"] == "date_time":
    # The direction follows where the date and time put the sun, which the extension states.
    for key in ("resolved_azimuth_deg", "resolved_elevation_deg", "resolved_true_azimuth_deg",
                "resolved_latitude_deg", "resolved_longitude_deg", "resolved_utc_offset_h"):
        expect(key in sun, f"sun.{key} missing in mode date_time")
    a, e = math.radians(sun.get("resolved_azimuth_deg", 0)), math.radians(sun.get("resolved_elevation_deg", 0))
else:
    expect(not any(k.startswith("resolved_") for k in sun), "resolved sun keys in mode manual")
    a, e = math.radians(psun["azimuth_deg"]), math.radians(psun["elevation_deg"])
toward = (math.sin(a) * math.cos(e), math.sin(e), -math.cos(a) * math.cos(e))
expect(all(close(x, y) for x, y in zip(sun["direction"], toward)),
       f"sun.direction {sun['direction']} is not toward azimuth/elevation {toward}")
expect(close(math.sqrt(sum(x * x for x in sun["direction"])), 1.0), "sun.direction is not unit")

shadows = ext["shadows"]
splits, rng = shadows["computed_splits"], shadows["computed_range"]
expect(len(splits) == cascades == project["shadows"]["cascades"], f"{len(splits)} splits for {cascades} cascades")
expect(all(x < y for x, y in zip([rng[0]] + splits, splits)), f"splits {splits} not increasing from {rng[0]}")
expect(splits[-1] == rng[1], f"last split {splits[-1]} is not the range's far end {rng[1]}")
expect(close(shadows["computed_for_aspect"], 16 / 9), "computed_for_aspect is not 16/9")
manual = project["shadows"]["splits"]
if project["shadows"]["split_mode"] == "manual" and all(rng[0] < x < rng[1] for x in manual):
    expect(splits[:-1] == manual, f"manual splits {manual} inside the range became {splits[:-1]}")

fog = ext["fog"]
if project["fog"]["base_height"] is None:
    expect(isinstance(fog["resolved_base_height"], (int, float)), "fog.resolved_base_height is not a number")
else:
    expect(fog["resolved_base_height"] == project["fog"]["base_height"], "fog.resolved_base_height differs")
if project["fog"]["color"] is not None:
    expect(fog["resolved_color"] == project["fog"]["color"], "fog.resolved_color differs")
elif mean_sky is not None:
    # The fog's ambient radiance, colour x luminance in scene units, is the sky's mean; 1 %: HDR
    # decoders differ by half a mantissa step.
    units = ext["scene_units_per_lux"] * fog["resolved_luminance"]
    ambient = [c * units for c in fog["resolved_color"]]
    expect(max(fog["resolved_color"]) == 1.0, f"fog.resolved_color {fog['resolved_color']} does not peak at 1")
    expect(all(close(x, y, 1e-2) for x, y in zip(ambient, mean_sky)),
           f"fog ambient {ambient} is not the sky's mean {mean_sky}")

# Water: every setting as the project prints it, the level and the waves resolved, and a water
# node with a transmissive material; none of it without water, nor where "auto" found no water in
# the DEM (resolved_level null).
used = doc.get("extensionsUsed", [])
water_nodes = [n for n in doc.get("nodes", []) if n.get("name") == "water"]
dry = project["water"]["enabled"] and project["water"]["level"] is None and \
    ext.get("water", {}).get("resolved_level", 0) is None
if dry:
    expect(not water_nodes, "a water node where auto found no water")
    expect("KHR_materials_transmission" not in used and "KHR_materials_ior" not in used,
           "material extensions where auto found no water")
elif project["water"]["enabled"]:
    w = ext.get("water")
    expect(w is not None, "no TERRALUX_lighting.water with water on")
    if w is not None:
        authored = {k: v for k, v in w.items() if not k.startswith("resolved_")}
        authored["waves"] = [{k: v for k, v in wave.items() if not k.startswith("resolved_")}
                             for wave in w["waves"]]
        expect(authored == project["water"],
               f"water: {json.dumps(authored, sort_keys=True)} != {json.dumps(project['water'], sort_keys=True)}")
        level = w["resolved_level"]
        if project["water"]["level"] is not None:
            expect(level == project["water"]["level"], "water.resolved_level is not the set level")
        for wave, pw in zip(w["waves"], project["water"]["waves"]):
            k = 2 * math.pi / pw["wavelength"]
            a = pw["amplitude"] if pw["amplitude"] is not None else pw["steepness"] / k
            az = math.radians(pw["direction_deg"])
            expect(close(wave["resolved_k"], k), f"resolved_k {wave['resolved_k']} != {k}")
            expect(close(wave["resolved_amplitude"], a), f"resolved_amplitude {wave['resolved_amplitude']} != {a}")
            expect(close(wave["resolved_omega"], math.sqrt(9.81 * k)), "resolved_omega is not sqrt(g k)")
            expect(all(close(x, y) for x, y in zip(wave["resolved_direction"], (math.sin(az), -math.cos(az)))),
                   f"resolved_direction {wave['resolved_direction']}")
        expect(len(water_nodes) == 1, f"{len(water_nodes)} water nodes")
        for name in ("KHR_materials_transmission", "KHR_materials_ior"):
            expect(name in used and name not in doc.get("extensionsRequired", []), f"{name} not used, or required")
        if water_nodes:
            mesh = doc["meshes"][water_nodes[0]["mesh"]]
            prim = mesh["primitives"][0]
            material = doc["materials"][prim["material"]]
            pos = doc["accessors"][prim["attributes"]["POSITION"]]
            expect(close(pos["min"][1], level) and close(pos["max"][1], level),
                   f"water plane at {pos['min'][1]}..{pos['max'][1]}, level {level}")
            terrain = doc["accessors"][doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]]
            expect(close(pos["min"][0], terrain["min"][0]) and close(pos["max"][2], terrain["max"][2]),
                   "water plane is not the terrain footprint")
            expect(material["extensions"]["KHR_materials_ior"]["ior"] == 1.33, "water ior is not 1.33")
            expect(material["extensions"]["KHR_materials_transmission"]["transmissionFactor"] == 1.0,
                   "water does not transmit")
            expect(all(close(x, y) for x, y in zip(material["pbrMetallicRoughness"]["baseColorFactor"],
                                                   project["water"]["color"] + [1.0])),
                   "water base colour is not water.color")
            expect(close(material["pbrMetallicRoughness"]["roughnessFactor"], project["water"]["roughness"]),
                   "water roughness is not water.roughness")
else:
    expect("water" not in ext, "TERRALUX_lighting.water without water")
    expect(not water_nodes, "a water node without water")
    expect("KHR_materials_transmission" not in used and "KHR_materials_ior" not in used,
           "material extensions without water")

for message in errors:
    print("FAIL:", message)
sys.exit(1 if errors else 0)
EOF
}

# validate SCENE_GLTF: zero errors, or skipped when the validator cannot be had.
validate() {
  "$validator" "$1" "$build" >"$work/validator.txt" 2>&1
  rc=$?
  [ $rc -eq 77 ] && { echo "note: glTF validator unavailable: $(tail -n 1 "$work/validator.txt")"; return 0; }
  [ $rc -eq 0 ] || { cat "$work/validator.txt"; fail "glTF validator reported errors in $1"; }
}

# The embedded sample, edited with --set.
sets=(--set shadows.cascades=3 --set fog.enabled=true --set fog.density=0.0001 --set sun.elevation_deg=12
      --set bake.error_map_resolution=0)
"$terralux" --print-project "${sets[@]}" >"$work/sample.json" || fail "--print-project exited $?"
"$terralux" --bake --quiet --quality draft "${sets[@]}" --out "$work/sample" >/dev/null || fail "bake exited $?"
# The default uniform sky, (0.6, 0.733, 1) × 5000 cd/m² = (0.09, 0.11, 0.15) scene units, is its own mean.
check "$work/sample.json" "$work/sample/scene.gltf" 3 0.09,0.11,0.15 || fail "sample: TERRALUX_lighting disagrees with --print-project"
validate "$work/sample/scene.gltf"

# A project file with a relative HDR sky: an 8 x 4 Radiance image of one radiance everywhere, and
# the authored sun beside it (an image without a sun of its own would otherwise light alone).
mkdir -p "$work/project/skies"
python3 - "$work/project/skies/even.hdr" <<'EOF' || fail "cannot write the test sky"
import sys
with open(sys.argv[1], "wb") as f:
    f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n")
    f.write(bytes([200, 160, 128, 130]) * 32)  # flat scanlines (too short for run-length encoding)
EOF
cat >"$work/project/lit.terralux.json" <<'EOF'
{
  "sky": {"mode": "hdr", "hdr": "skies/even.hdr", "color": [1, 1, 1], "intensity": 0.5},
  "sun": {"follow_sky": false},
  "shadows": {"cascades": 2, "split_mode": "manual", "splits": [9000]},
  "fog": {"enabled": true, "base_height": 800, "color": null},
  "camera": {"exposure_ev": 1.5},
  "bake": {"error_map_resolution": 0}
}
EOF
"$terralux" --print-project "$work/project/lit.terralux.json" --set sun.azimuth_deg=250 >"$work/lit.json" ||
  fail "--print-project of the project file exited $?"
(cd "$work" && "$terralux" --bake --quiet --quality draft project/lit.terralux.json --set sun.azimuth_deg=250 \
  --out "$work/lit" >/dev/null) || fail "bake of the project file exited $?"
grep -q '"hdr": "skies/even.hdr"' "$work/lit.json" || fail "--print-project rewrote the HDR path"
# Radiance's RGBE: (mantissa + 0.5) × 2^(exponent − 136), then × intensity.
mean=$(python3 -c 'print(",".join(str((m + 0.5) * 2.0 ** (130 - 136) * 0.5) for m in (200, 160, 128)))')
check "$work/lit.json" "$work/lit/scene.gltf" 2 "$mean" || fail "project file: TERRALUX_lighting disagrees with --print-project"
validate "$work/lit/scene.gltf"

# Lighting scenarios: each listed after the default with its files, its sun and sky the project's
# scenario as --print-project prints it (plus what the extension adds), its .shprobe the header
# and occupancy of the default's with coefficients of its own; the validator accepts the scene.
cat >"$work/scenarios.terralux.json" <<'EOF'
{
  "probe_volumes": [{"name": "valley", "grid_dims": [5, 4]}, {"name": "peaks", "grid_dims": [3, 3], "height_offset": 50}],
  "scenarios": [{"name": "dusk", "sun": {"azimuth_deg": 250, "elevation_deg": 6, "illuminance": 40000}, "sky": {"intensity": 0.4}},
                {"name": "overcast", "sun": {"illuminance": 0}, "sky": {"intensity": 2.5, "color": [0.95, 0.95, 1], "luminance": 8000}}],
  "bake": {"error_map_resolution": 0}
}
EOF
"$terralux" --print-project "$work/scenarios.terralux.json" >"$work/scenarios.json" || fail "--print-project of the scenarios exited $?"
"$terralux" --bake --quiet --quality draft "$work/scenarios.terralux.json" --out "$work/scenarios" >/dev/null ||
  fail "bake of the scenarios exited $?"
python3 - "$work/scenarios.json" "$work/scenarios" <<'PY' || fail "scenarios: TERRALUX_lighting.scenarios or the files disagree with the project"
import json, os, sys
project = json.load(open(sys.argv[1]))
out = sys.argv[2]
scene = json.load(open(os.path.join(out, "scene.gltf")))["scenes"][0]["extensions"]
ext, grids = scene["TERRALUX_lighting"], scene["VULKAN_SCHNEE_engine_properties"]["shProbeGrids"]
errors = []
names = [s["name"] for s in ext["scenarios"]]
if names != ["default", "dusk", "overcast"]:
    errors.append(f"scenario names {names}")
if [g["shProbePath"] for g in grids] != ext["scenarios"][0]["shProbePaths"]:
    errors.append("the default's files are not shProbeGrids'")
for entry, authored in zip(ext["scenarios"][1:], project["scenarios"]):
    for section in ("sun", "sky"):
        plain = {k: v for k, v in entry[section].items() if k != "direction" and not k.startswith("resolved_")}
        if plain != authored[section]:
            errors.append(f"{entry['name']}.{section}: {plain} != {authored[section]}")
    want = [p.replace("sh_coeffs/", "scenarios/").replace(".shprobe", "." + entry["name"] + ".shprobe")
            for p in ext["scenarios"][0]["shProbePaths"]]
    if entry["shProbePaths"] != want:
        errors.append(f"{entry['name']} files {entry['shProbePaths']} != {want}")
    for mine, default in zip(entry["shProbePaths"], ext["scenarios"][0]["shProbePaths"]):
        a, b = open(os.path.join(out, mine), "rb").read(), open(os.path.join(out, default), "rb").read()
        count = int.from_bytes(b[8:12], "little")
        occupancy = 48 + 160 * count
        if len(a) != len(b) or a[:48] != b[:48] or a[occupancy:] != b[occupancy:]:
            errors.append(f"{mine}: not the layout of {default}")
        elif a == b:
            errors.append(f"{mine}: the default's coefficients")
for e in errors:
    print("FAIL:", e)
sys.exit(1 if errors else 0)
PY
validate "$work/scenarios/scene.gltf"

# The sample with a lake at 800 m (its valleys are at 529 m), two waves, and the albedo texture beside it.
sets=(--set water.enabled=true --set water.level=800 --set water.roughness=0.2 --set water.depth_aware=true --set bake.error_map_resolution=0
      --set 'water.waves=[{"direction_deg":60,"wavelength":30,"steepness":0.2},{"wavelength":7,"amplitude":0.15,"phase":2}]')
"$terralux" --print-project "${sets[@]}" >"$work/lake.json" || fail "--print-project of the lake exited $?"
"$terralux" --bake --quiet --quality draft "${sets[@]}" --out "$work/lake" >/dev/null || fail "bake of the lake exited $?"
check "$work/lake.json" "$work/lake/scene.gltf" 4 0.09,0.11,0.15 || fail "lake: TERRALUX_lighting or the water node disagrees with --print-project"
validate "$work/lake/scene.gltf"

# "auto" on the sample, a dry range: no water surface in the DEM, so none is baked or exported,
# the level resolves to null, and the bake says why on stderr.
sets=(--set water.enabled=true --set bake.error_map_resolution=0)
"$terralux" --print-project "${sets[@]}" >"$work/dry.json" || fail "--print-project of the dry lake exited $?"
"$terralux" --bake --quality draft "${sets[@]}" --out "$work/dry" >/dev/null 2>"$work/dry.err" ||
  fail "bake of the dry lake exited $?"
grep -q "^terralux: warning: water.level auto: the DEM shows no water surface" "$work/dry.err" ||
  fail "no warning for auto water on a dry DEM: $(cat "$work/dry.err")"
check "$work/dry.json" "$work/dry/scene.gltf" 4 0.09,0.11,0.15 || fail "dry: the water was exported where auto found none"
validate "$work/dry/scene.gltf"

# The sun from a date and a time over the sample (UTM 11N, 34.34° N 118.21° W): the extension's
# direction is the resolved one, and the bake says where the sun stood.
sets=(--set sun.mode=date_time --set sun.date=2026-06-21 --set sun.time_h=7.5 --set sun.utc_offset_h=-7
      --set bake.error_map_resolution=0)
"$terralux" --print-project "${sets[@]}" >"$work/dated.json" || fail "--print-project of the dated sun exited $?"
"$terralux" --bake --quality draft "${sets[@]}" --out "$work/dated" >"$work/dated.out" 2>&1 || fail "bake of the dated sun exited $?"
check "$work/dated.json" "$work/dated/scene.gltf" 4 0.09,0.11,0.15 || fail "dated sun: TERRALUX_lighting disagrees"
grep -q "^  sun: 2026-06-21 07:30 at UTC-7.00 over 34.3374° N, 118.2142° W: azimuth " "$work/dated.out" ||
  fail "the bake does not say where the sun stood: $(cat "$work/dated.out")"
python3 - "$work/dated/bake_report.json" <<'EOF' || fail "bake_report.json: sun"
import json, sys
sun = json.load(open(sys.argv[1]))["sun"]
# Morning in June at 34° N: north of east, about 20° up.
assert 70 < sun["true_azimuth_deg"] < 80 and 18 < sun["elevation_deg"] < 22, sun
assert abs(sun["azimuth_deg"] - sun["true_azimuth_deg"] - 0.68) < 0.02, sun  # grid north 0.68° west of true
EOF
# A DEM without a CRS has no place on the Earth: the mode needs one set by hand.
python3 - "$work/nocrs.asc" <<'EOF'
import sys
with open(sys.argv[1], "w") as f:
    f.write("ncols 8\nnrows 8\nxllcorner 0\nyllcorner 0\ncellsize 30\n")
    for r in range(8):
        f.write(" ".join(str(100 + 10 * r + c) for c in range(8)) + "\n")
EOF
"$terralux" --bake --quality draft --dem "$work/nocrs.asc" --set sun.mode=date_time --out "$work/nocrs" \
  >/dev/null 2>"$work/nocrs.err" && fail "date_time over a DEM without a CRS was baked"
grep -q "sun.mode: date_time places the sun over the DEM $work/nocrs.asc, which carries no CRS: set sun.latitude_deg and sun.longitude_deg" \
  "$work/nocrs.err" || fail "no place, no clear error: $(cat "$work/nocrs.err")"
"$terralux" --bake --quiet --quality draft --dem "$work/nocrs.asc" --set sun.mode=date_time --set sun.latitude_deg=47.9 \
  --set sun.longitude_deg=102.8 --set bake.error_map_resolution=0 --out "$work/nocrs" >/dev/null ||
  fail "date_time with a place set by hand exited $?"
echo "ok"
