#!/usr/bin/env bash
# The project JSON Schema (--print-schema) accepts what --print-project prints, for every kind of
# probe volume, and rejects what the tool rejects. Also: an unknown key in a project file is an
# error (exit 2), never a default. Usage: schema_checks.sh TERRALUX OUTDIR
set -uo pipefail
terralux=$1 out=$2
python3 -c 'import jsonschema; jsonschema.Draft202012Validator' 2>/dev/null ||
  { echo "SKIP: python3-jsonschema not installed (Debian: python3-jsonschema)"; exit 77; }
rm -rf "$out" && mkdir -p "$out"
fail() { echo "FAIL: $*"; exit 1; }

"$terralux" --print-schema >"$out/schema.json" || fail "--print-schema exited $?"
validate() {  # validate FILE EXPECT(valid|invalid)
  python3 - "$out/schema.json" "$1" "$2" <<'PY'
import json, sys, jsonschema
schema = json.load(open(sys.argv[1]))
jsonschema.Draft202012Validator.check_schema(schema)
errors = list(jsonschema.Draft202012Validator(schema).iter_errors(json.load(open(sys.argv[2]))))
if sys.argv[3] == "valid" and errors:
    sys.exit(f"{sys.argv[2]}: {errors[0].json_path}: {errors[0].message}")
if sys.argv[3] == "invalid" and not errors:
    sys.exit(f"{sys.argv[2]}: the schema accepts what the tool rejects")
PY
}

# Every leaf has a description and a default.
python3 - "$out/schema.json" <<'PY' || fail "schema leaves"
import json, sys
def walk(node, path):
    if node.get("type") == "object" and "properties" in node:
        for k, v in node["properties"].items():
            if k == "$schema":
                continue
            walk(v, path + "." + k if path else k)
    elif node.get("type") == "array" and isinstance(node.get("items"), dict) and node["items"].get("type") == "object":
        walk(node["items"], path + "[]")
    else:
        for key in ("description", "default"):
            if key not in node:
                sys.exit(f"{path}: no {key}")
walk(json.load(open(sys.argv[1])), "")
PY

# A 4 x 2 Radiance HDR sky (flat RGBE scanlines, allowed below 8 pixels wide).
python3 -c '
import sys
with open(sys.argv[1], "wb") as f:
    f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n" + bytes([128, 128, 128, 129]) * 8)' "$out/sky.hdr"
i=0
for sets in "" \
  "--set sun.elevation_deg=-5 --set sky.mode=hdr --set sky.hdr=$out/sky.hdr" \
  "--set probe_volumes[0].placement=box --set probe_volumes[0].grid_dims=4,2,3 --set probe_volumes[0].spacing=50 --set probe_volumes[0].origin=0,100,0" \
  "--set probe_volumes[0].placement=adaptive --set probe_volumes[0].adaptive.size=3000,1200,2000 --set probe_volumes[0].adaptive.tolerance=0.03" \
  "--set bake.rays=128 --set bake.bounces=0 --set camera.radius=5000 --set camera.target=0,10,0" \
  "--set water.enabled=true --set water.level=700 --set water.waves=[{\"wavelength\":20,\"steepness\":0.2},{\"direction_deg\":30,\"wavelength\":5,\"amplitude\":0.1}]"; do
  i=$((i + 1))
  # shellcheck disable=SC2086
  "$terralux" --print-project $sets >"$out/project$i.json" || fail "--print-project $sets exited $?"
  validate "$out/project$i.json" valid || fail "--print-project $sets does not validate"
  # What the tool prints, it reads back unchanged.
  "$terralux" --print-project "$out/project$i.json" >"$out/again$i.json" || fail "re-reading project$i.json"
  cmp -s "$out/project$i.json" "$out/again$i.json" || fail "project$i.json does not round-trip"
done

# A misspelt key: the schema flags it, and the tool refuses the file naming it.
python3 - "$out/project1.json" "$out/misspelt.json" <<'PY'
import json, sys
p = json.load(open(sys.argv[1]))
p["sun"]["elevaton_deg"] = p["sun"].pop("elevation_deg")
json.dump(p, open(sys.argv[2], "w"))
PY
validate "$out/misspelt.json" invalid || fail "schema accepts sun.elevaton_deg"
"$terralux" --print-project "$out/misspelt.json" >/dev/null 2>"$out/err.txt"
code=$?
[ $code -eq 2 ] || fail "misspelt key: exit $code, expected 2"
grep -q "misspelt.json: unknown key 'sun.elevaton_deg'.*did you mean 'sun.elevation_deg'" "$out/err.txt" ||
  fail "misspelt key message: $(cat "$out/err.txt")"
"$terralux" --bake --quiet "$out/misspelt.json" --out "$out/never" 2>/dev/null
[ $? -eq 2 ] && [ ! -e "$out/never" ] || fail "--bake with a misspelt key must exit 2 and write nothing"

# Out of range: both refuse.
python3 - "$out/project1.json" "$out/range.json" <<'PY'
import json, sys
p = json.load(open(sys.argv[1]))
p["sun"]["elevation_deg"] = 91
json.dump(p, open(sys.argv[2], "w"))
PY
validate "$out/range.json" invalid || fail "schema accepts sun.elevation_deg = 91"
"$terralux" --print-project "$out/range.json" >/dev/null 2>&1
[ $? -eq 2 ] || fail "sun.elevation_deg = 91 must exit 2"
echo "schema checks passed ($i projects)"
