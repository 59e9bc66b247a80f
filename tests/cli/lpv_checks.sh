#!/usr/bin/env bash
# lpv_checks.sh TERRALUX VALIDATOR WORKDIR BUILD_DIR
# Light propagation volumes leave the bake as lpv.ini and TERRALUX_lighting.lpv, local lights as
# KHR_lights_punctual: the ini's values are --print-project's lpv section, in the table's order;
# the lights are the project's (cone angles in radians, spots turned onto their direction); the
# Khronos validator finds no error; a bake with the LPV off removes the earlier lpv.ini.
set -u
terralux=$1 validator=$2 work=$3 build=$4
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }

sets=(--set lpv.enabled=true --set lpv.cascades=2 --set lpv.size=4000 --set lpv.propagation_weight=0.125
      --set lpv.quality=2 --set lpv.indirect_intensity=1.5 --set lighting.indirect=both
      --set bake.error_map_resolution=0 --set camera.target=0,1200,0 --set camera.radius=600
      --set 'lights=[{"position":[0,1500,0],"intensity":6.0e8,"range":400,"color":[1,0.8,0.6]},{"type":"spot","position":[300,1600,-200],"direction":[0.2,-1,0.1],"inner_cone_deg":15,"outer_cone_deg":35,"range":900},{"position":[0,1500,0],"range":1}]')
"$terralux" --print-project "${sets[@]}" >"$work/project.json" || fail "--print-project exited $?"
"$terralux" --bake --quiet --quality draft "${sets[@]}" --out "$work/bake" >"$work/stdout.txt" 2>"$work/stderr.txt" ||
  { cat "$work/stderr.txt"; fail "bake exited $?"; }
[ -f "$work/bake/lpv.ini" ] || fail "no lpv.ini"
grep -q "^  light propagation volumes: 2 cascades (4000, 768 m), 2 of 3 lights injected$" "$work/stdout.txt" ||
  { cat "$work/stdout.txt"; fail "the bake's summary does not name the cascades and lights"; }
grep -Eq "warning: lights\[2\]: not injected into the light propagation volumes: range 1 m is below cascade [01]'s cell \((24|125) m\) \(for the project's camera\)$" "$work/stderr.txt" ||
  { cat "$work/stderr.txt"; fail "no warning for the light too small for its cascade"; }

python3 - "$work/project.json" "$work/bake/lpv.ini" "$work/bake/scene.gltf" <<'EOF' || exit 1
import json, math, sys
project = json.load(open(sys.argv[1]))
ini = open(sys.argv[2]).read()
doc = json.load(open(sys.argv[3]))
errors = []
def expect(ok, what):
    if not ok:
        errors.append(what)

# lpv.ini: the section, then one line per key of the project's lpv section in the table's order
# (the order of `names`; the printed project sorts its keys).
names = {"enabled": "rEx.GI.Method", "size": "rEx.LPV.Size", "fade_range": "rEx.LPV.FadeRange",
         "propagation_weight": "rEx.LPV.PropagationWeight",
         "propagation_iterations": "rEx.LPV.PropagationIterations",
         "update_interval": "rEx.LPV.UpdateInterval", "cascades": "rEx.LPV.NumCascades",
         "cascade_ratio": "rEx.LPV.CascadeRatio", "auto_cascade_min_size": "rEx.LPV.AutoCascadeMinSize",
         "cascade_forward_offset": "rEx.LPV.CascadeForwardOffset",
         "local_lights": "rEx.LPV.EnableLocalLights", "quality": "rEx.LPV.Quality",
         "cone_trace_samples": "rEx.LPV.ConeTraceSamples"}
lines = ini.split("\n")
expect(lines[0] == "[SystemSettings]", f"first line {lines[0]!r}")
pairs = [l.split("=", 1) for l in lines[1:] if l and not l.startswith(";")]
lpv = project["lpv"]
expected = [(name, lpv[k]) for k, name in names.items()]
expect([p[0] for p in pairs] == [e[0] for e in expected], f"ini names {[p[0] for p in pairs]}")
for (name, text), (_, value) in zip(pairs, expected):
    expect(float(text) == float(value), f"{name}={text}, project {value}")
expect(f"; IndirectLightingIntensity={lpv['indirect_intensity']}" in ini, "no IndirectLightingIntensity comment")

ext = doc["scenes"][0]["extensions"]["TERRALUX_lighting"]
authored = {k: v for k, v in ext["lpv"].items()
            if k not in ("console_variables", "ini_uri") and not k.startswith("computed_")}
expect(authored == lpv, f"TERRALUX_lighting.lpv {authored} != {lpv}")
expect(ext["lpv"]["console_variables"] == {n: float(t) if "." in t else int(t) for n, t in pairs},
       "console_variables are not the ini's")
# auto_cascade_min_size 768 raises the ratio to 4000 / 768.
sizes = ext["lpv"]["computed_cascade_sizes"]
expect(len(sizes) == 2 and sizes[0] == 4000 and abs(sizes[1] - 768) < 1e-9, f"sizes {sizes}")
expect(ext["indirect"] == project["lighting"]["indirect"] == "both", "indirect differs")

# KHR_lights_punctual: one light and one node per project light.
used = doc.get("extensionsUsed", [])
expect("KHR_lights_punctual" in used and "KHR_lights_punctual" not in doc.get("extensionsRequired", []),
       "KHR_lights_punctual not used, or required")
lights = doc["extensions"]["KHR_lights_punctual"]["lights"]
expect(len(lights) == len(project["lights"]) == 3, f"{len(lights)} lights")
nodes = {n["extensions"]["KHR_lights_punctual"]["light"]: (k, n) for k, n in enumerate(doc["nodes"])
         if "KHR_lights_punctual" in n.get("extensions", {})}
in_scene = {x for sc in doc["scenes"] for x in sc["nodes"]}
for i, (light, pl) in enumerate(zip(lights, project["lights"])):
    expect(light["type"] == pl["type"], f"light {i} type")
    # Candela, as the project authors it (the sun's illuminance is lux).
    expect(light["intensity"] == pl["intensity"] and light["range"] == pl["range"],
           f"light {i} intensity/range")
    expect(all(abs(a - b) < 1e-6 for a, b in zip(light["color"], pl["color"])), f"light {i} colour")
    index, node = nodes.get(i, (None, {}))
    expect(node.get("translation") == pl["position"], f"light {i} node")
    expect(index in in_scene, f"light {i} not in the scene")
    if pl["type"] == "spot":
        expect(abs(light["spot"]["innerConeAngle"] - math.radians(pl["inner_cone_deg"])) < 1e-12, "inner cone")
        expect(abs(light["spot"]["outerConeAngle"] - math.radians(pl["outer_cone_deg"])) < 1e-12, "outer cone")
        x, y, z, w = node["rotation"]
        # −Z turned by the quaternion.
        v = (0.0, 0.0, -1.0)
        t = [2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])]
        r = [v[0] + w * t[0] + (y * t[2] - z * t[1]), v[1] + w * t[1] + (z * t[0] - x * t[2]),
             v[2] + w * t[2] + (x * t[1] - y * t[0])]
        d = pl["direction"]
        n = math.sqrt(sum(c * c for c in d))
        expect(all(abs(a - b / n) < 1e-5 for a, b in zip(r, d)), f"spot points along {r}, not {d}")
for message in errors:
    print("FAIL:", message)
sys.exit(1 if errors else 0)
EOF

"$validator" "$work/bake/scene.gltf" "$build" >"$work/validator.txt" 2>&1
rc=$?
if [ $rc -eq 77 ]; then
  echo "note: glTF validator unavailable: $(tail -n 1 "$work/validator.txt")"
elif [ $rc -ne 0 ]; then
  cat "$work/validator.txt"; fail "glTF validator reported errors"
fi

# The LPV off: the next bake into the same folder removes lpv.ini, and no lights means no extension.
"$terralux" --bake --quiet --quality draft --set bake.error_map_resolution=0 --out "$work/bake" >/dev/null ||
  fail "second bake exited $?"
[ ! -e "$work/bake/lpv.ini" ] || fail "lpv.ini of the earlier bake is still there"
grep -q KHR_lights_punctual "$work/bake/scene.gltf" && fail "KHR_lights_punctual without lights"
grep -q '"lpv"' "$work/bake/scene.gltf" && fail "TERRALUX_lighting.lpv with the LPV off"
# The dry run names what the LPV adds.
"$terralux" --bake --dry-run --quiet "${sets[@]}" | grep -q "light propagation volumes: lpv.ini" ||
  fail "the dry run does not mention lpv.ini"
echo "ok"
