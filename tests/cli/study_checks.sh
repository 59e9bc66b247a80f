#!/usr/bin/env bash
# study_checks.sh TERRALUX WORKDIR
# `terralux --study --budget 20` on the embedded sample: finishes within the budget + 20 %, writes
# a study.json whose points carry every measured quantity (the project's settings first, the
# Pareto front marked and consistent), a study.csv with a row per point, a study.png that decodes
# (OpenImageIO reads every pixel), and a study.html that shows the PNG and lists every point.
set -u
terralux=$1 work=$2
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }

start=$(date +%s.%N)
"$terralux" --study --quiet --budget 20 --out "$work/study" >"$work/stdout.txt" 2>"$work/stderr.txt" ||
  { cat "$work/stderr.txt"; fail "--study exited $?"; }
end=$(date +%s.%N)
python3 -c "import sys; t=$end-$start; print(f'study took {t:.1f} s'); sys.exit(0 if t <= 24.0 else 1)" ||
  fail "the study overran its 20 s budget by more than 20 %"
[ -s "$work/stderr.txt" ] && { cat "$work/stderr.txt"; fail "the study wrote to stderr"; }
grep -q "^wrote " "$work/stdout.txt" || fail "no summary on stdout"

for f in study.json study.csv study.png study.html; do [ -s "$work/study/$f" ] || fail "no $f"; done
ls "$work/study" | grep -q tmp && fail "a temporary file was left behind"
oiiotool "$work/study/study.png" --printstats >"$work/stats.txt" 2>&1 || { cat "$work/stats.txt"; fail "study.png does not decode"; }
grep -q "1280 x  *800" "$work/stats.txt" || grep -q "1280 x 800" "$work/stats.txt" || { cat "$work/stats.txt"; fail "study.png is not 1280 x 800"; }

python3 - "$work/study" <<'PY' || exit 1
import csv, json, math, sys, html.parser
d = sys.argv[1]
s = json.load(open(d + "/study.json"))
errors = []
def expect(ok, what):
    if not ok: errors.append(what)
pts = s["points"]
expect(s["budget_s"] == 20, "budget_s is not 20")
expect(s["elapsed_s"] <= 24, "elapsed_s over the budget + 20 %")
expect(s["reference"]["points"] >= 36 and s["reference"]["rays_per_point"] >= 1024, "reference too small")
expect(pts and pts[0]["knob"] == "current" and pts[0]["current"], "the project's settings are not the first point")
knobs = {p["knob"] for p in pts}
# Every knob is measured, or skipped or left out with its reason (a slow machine, a sanitizer build).
accounted = knobs | {k["knob"] for k in s["skipped"]} | {n.split(":")[0] for n in s["not_studied"]}
for k in ("quality", "rays", "bounces", "spacing", "error_map", "ao_directions", "shadow_cascades", "shadow_resolution",
          "shadow_filter"):
    expect(k in accounted, "knob %s neither studied nor said to be left out" % k)
for k in ("rays", "spacing"):
    expect(k in knobs, "knob %s not studied" % k)
for p in pts:
    for key in ("time_s", "peak_memory_bytes", "output_bytes", "probes", "error", "set", "metric", "points"):
        expect(key in p, "%s lacks %s" % (p["label"], key))
    e = p["error"]
    expect(all(math.isfinite(e[k]) and e[k] >= 0 for k in ("mean", "p95", "max")), "%s: bad error" % p["label"])
    expect(e["mean"] <= e["max"] + 1e-12 and e["p95"] <= e["max"] + 1e-12, "%s: mean/p95 above max" % p["label"])
    expect(p["time_s"] > 0, "%s: no time" % p["label"])
    if p["knob"] != "current": expect(p["set"], "%s: no --set to reproduce it" % p["label"])
# The front: irradiance points only; none of them dominated by another irradiance point.
irr = [p for p in pts if p["metric"] == "irradiance"]
front = [p for p in irr if p["pareto"]]
expect(front, "no Pareto front")
for f in front:
    for q in irr:
        better = q["time_s"] <= f["time_s"] and q["error"]["p95"] <= f["error"]["p95"] and \
                 (q["time_s"] < f["time_s"] or q["error"]["p95"] < f["error"]["p95"])
        expect(not better, "%s on the front but %s is faster and better" % (f["label"], q["label"]))
for q in irr:
    if q["pareto"]: continue
    dominated = any(f["time_s"] <= q["time_s"] and f["error"]["p95"] <= q["error"]["p95"] for f in front)
    expect(dominated, "%s is off the front but nothing on it beats it" % q["label"])
# Denser probes lower the interpolation-dominated error on this terrain: the densest grid studied
# (the spacing sweep, or the dense placements measured with another preset, which a slow build
# reaches first) errs less at p95 than the sparsest. Neighbouring counts need not be monotone:
# a 6x6 grid can sit worse on the ridges than a 4x4 one.
sp = sorted([p for p in pts if p["knob"] in ("spacing", "placement_quality")], key=lambda p: p["probes"])
expect(len(sp) >= 2 and sp[-1]["probes"] >= 4 * sp[0]["probes"], "the spacing sweep spans too few probe counts")
expect(sp and sp[-1]["error"]["p95"] < sp[0]["error"]["p95"], "denser grids do not lower the error")
rows = list(csv.DictReader(open(d + "/study.csv")))
expect(len(rows) == len(pts), "study.csv has %d rows for %d points" % (len(rows), len(pts)))
page = open(d + "/study.html").read()
expect('src="study.png"' in page, "study.html does not show study.png")
for p in pts:
    expect(html.escape(p["label"]) in page, "study.html does not list %s" % p["label"])
if errors:
    print("FAIL:\n  " + "\n  ".join(errors)); sys.exit(1)
print("study: %d points, %d on the front, %.1f s" % (len(pts), len(front), s["elapsed_s"]))
PY
echo "PASS"
