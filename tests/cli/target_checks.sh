#!/usr/bin/env bash
# target_checks.sh CASE TERRALUX WORKDIR DEM
# probe_volumes[].target_error end to end on a committed DEM crop: the bake meets the target on
# its own error map and says why it chose what it did; the dry run says the same and writes
# nothing; a target past the terrain-grid limit is one plain warning whose surface-volume offer
# delivers; an adaptive or surface volume's target chooses its tolerance the same way.
set -u
case_=$1 terralux=$2 work=$3 dem=$4
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }
p95() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['volumes'][0]['$1']['p95'])" "$work/out/bake_report.json"; }
case "$case_" in
  meets)
    "$terralux" --bake --quiet --quality draft --dem "$dem" --out "$work/out" \
      --set 'probe_volumes[0].target_error=0.1' >"$work/stdout" 2>"$work/stderr" || fail "bake exited $?"
    python3 - "$work/out/bake_report.json" <<'PY' || fail "bake_report.json"
import json, sys
v = json.load(open(sys.argv[1]))["volumes"][0]
t, m = v["target"], v["error_map"]
assert m["points"] > 1000, m
assert m["p95"] <= 0.1, f"error map p95 {m['p95']} above the target 0.1"
assert t["target"] == 0.1 and t["met"] is True and t["capped"] is False, t
assert t["setting"] == "grid_dims" and t["replaced"] == "8,8", t
nx, nz = (int(x) for x in t["value"].split(","))
assert v["probe_grid"] == [nx, 1, nz] and v["probes"] == t["probes"] == nx * nz, (v["probe_grid"], t)
assert nx * nz <= 4096 and nx * nz > 64, t
assert abs(t["p95"] - m["p95"]) < 1e-9, (t, m)
assert t["summary"].startswith("spacing ") and "probes, p95 " in t["summary"], t
PY
    grep -Eq "^    target_error 10.0 %: grid_dims [0-9]+,[0-9]+ \(replaces 8,8\): spacing [0-9]+ m, [0-9 ]+ probes, p95 [0-9.]+ % \(meets it\)$" \
      "$work/stdout" || fail "stdout does not explain the choice"
    [ -s "$work/stderr" ] && fail "stderr not empty: $(cat "$work/stderr")"
    ;;
  dry_run)
    "$terralux" --bake --dry-run --quiet --quality draft --dem "$dem" --out "$work/out" \
      --set 'probe_volumes[0].target_error=0.1' >"$work/stdout" 2>"$work/stderr" || fail "dry run exited $?"
    grep -q "^dry run: nothing baked, nothing written" "$work/stdout" || fail "no dry-run header"
    grep -Eq "^    target_error 10.0 %: grid_dims [0-9]+,[0-9]+ \(replaces 8,8\): spacing [0-9]+ m, [0-9 ]+ probes, p95 [0-9.]+ % on a 64-point map \(meets it; [0-9]+ trials" \
      "$work/stdout" || fail "no choice in the dry run"
    grep -Eq "^  probes: terrain grid, .*: [0-9]+ probes, [0-9]+ bytes, .* about" "$work/stdout" || fail "no cost"
    [ -e "$work/out" ] && fail "the dry run created $work/out"
    [ -s "$work/stderr" ] && fail "stderr not empty"
    ;;
  capped)
    # 5 % on this crop needs more than 4096 probes: the densest grid, one warning line.
    "$terralux" --bake --quiet --quality draft --dem "$dem" --out "$work/out" \
      --set 'probe_volumes[0].target_error=0.05' >"$work/stdout" 2>"$work/stderr" || fail "bake exited $?"
    [ "$(wc -l <"$work/stderr")" = 1 ] || fail "want one stderr line, got: $(cat "$work/stderr")"
    grep -Eq "^terralux: warning: probe_volumes\[0\].target_error 5.0 % needs more than the 4096 probes a terrain grid may hold: baking the densest allowed, grid_dims [0-9]+,[0-9]+ \(p95 [0-9.]+ %\); a surface volume meets it: --set probe_volumes\[0\].placement=surface \(tolerance [0-9.e-]+, [0-9 ]+ probes, [0-9 ]+ bytes, about [0-9.]+ s, p95 [0-9.]+ %\)$" \
      "$work/stderr" || fail "no plain warning: $(cat "$work/stderr")"
    python3 - "$work/out/bake_report.json" <<'PY' || fail "bake_report.json"
import json, sys
r = json.load(open(sys.argv[1]))
v = r["volumes"][0]
assert v["probes"] <= 4096 and v["probes"] > 3500, v["probes"]
assert v["target"]["capped"] is True and v["target"]["met"] is False, v["target"]
assert len(r["warnings"]) == 1 and "4096 probes" in r["warnings"][0], r["warnings"]
assert v["target"]["offer"]["set"] == ["probe_volumes[0].placement=surface", "probe_volumes[0].target_error=0.05"], v["target"]
PY
    # The offer delivers: baked as it says, the surface volume meets 5 % on its own map.
    "$terralux" --bake --quiet --quality draft --dem "$dem" --out "$work/offer" \
      --set 'probe_volumes[0].placement=surface' --set 'probe_volumes[0].target_error=0.05' \
      >"$work/offer_stdout" 2>"$work/offer_stderr" || fail "the offered bake exited $?"
    python3 - "$work/offer/bake_report.json" <<'PY' || fail "the offered bake's report"
import json, sys
v = json.load(open(sys.argv[1]))["volumes"][0]
assert v["placement"] == "surface" and v["adaptive"]["tree"] == "quadtree", v["placement"]
assert v["target"]["met"] is True and v["error_map"]["p95"] <= 0.05, (v["target"], v["error_map"])
PY
    ;;
  surface)
    # A surface volume: the dry run names the quadtree and its squares, the bake meets its target
    # at its probes' height with fewer probes than a uniform grid of its smallest squares.
    set -- --quality draft --dem "$dem" --set 'probe_volumes[0].placement=surface' \
      --set 'probe_volumes[0].target_error=0.1'
    "$terralux" --bake --dry-run --quiet --out "$work/dry" "$@" >"$work/dry_stdout" 2>"$work/dry_stderr" \
      || fail "dry run exited $?"
    grep -Eq "^  probes: surface quadtree, squares [0-9.]+ to [0-9.]+ m, [0-9]+ x [0-9]+ x [0-9]+ cells of [0-9.]+ m: [0-9]+ probes \(a uniform grid of the smallest squares would need [0-9]+\)" \
      "$work/dry_stdout" || fail "no quadtree in the dry run: $(cat "$work/dry_stdout")"
    "$terralux" --bake --quiet --out "$work/out" "$@" >"$work/stdout" 2>"$work/stderr" || fail "bake exited $?"
    [ -s "$work/stderr" ] && fail "stderr not empty: $(cat "$work/stderr")"
    python3 - "$work/out/bake_report.json" <<'PY' || fail "bake_report.json"
import json, sys
v = json.load(open(sys.argv[1]))["volumes"][0]
t, m, a = v["target"], v["error_map"], v["adaptive"]
assert t["setting"] == "adaptive.tolerance" and t["met"] is True, t
assert m["height_m"] == 5.0 and m["p95"] <= 0.1, m
assert a["tree"] == "quadtree" and v["probes"] < a["uniform_grid_probes"] / 2, (v["probes"], a)
PY
    ;;
  adaptive)
    # An adaptive volume's target sets adaptive.tolerance; the dry run names the same choice.
    set -- --quality draft --dem "$dem" --set 'probe_volumes[0].placement=adaptive' \
      --set 'probe_volumes[0].target_error=0.2'
    "$terralux" --bake --dry-run --quiet --out "$work/dry" "$@" >"$work/dry_stdout" 2>"$work/dry_stderr" \
      || fail "dry run exited $?"
    grep -q "^dry run: nothing baked, nothing written" "$work/dry_stdout" || fail "no dry-run header"
    choice='^    target_error 20.0 %: adaptive.tolerance ([0-9.e-]+): min cell [0-9]+ m, tolerance [0-9.]+ %, [0-9 ]+ probes, p95 [0-9.]+ %'
    grep -Eq "$choice on a [0-9]+-point map \(meets it; [0-9]+ trials" "$work/dry_stdout" \
      || fail "no choice in the dry run: $(cat "$work/dry_stdout")"
    [ -e "$work/dry" ] && fail "the dry run created $work/dry"
    [ -s "$work/dry_stderr" ] && fail "dry-run stderr not empty: $(cat "$work/dry_stderr")"
    "$terralux" --bake --quiet --out "$work/out" "$@" >"$work/stdout" 2>"$work/stderr" || fail "bake exited $?"
    grep -Eq "$choice \(meets it\)$" "$work/stdout" || fail "stdout does not explain the choice: $(cat "$work/stdout")"
    [ -s "$work/stderr" ] && fail "stderr not empty: $(cat "$work/stderr")"
    python3 - "$work/out/bake_report.json" <<'PY' || fail "bake_report.json"
import json, sys
v = json.load(open(sys.argv[1]))["volumes"][0]
t, m = v["target"], v["error_map"]
assert t["setting"] == "adaptive.tolerance" and t["replaced"] is None, t
assert t["target"] == 0.2 and t["met"] is True and t["capped"] is False, t
assert m["points"] > 100 and m["p95"] <= 0.2 and abs(t["p95"] - m["p95"]) < 1e-9, (t, m)
assert v["probes"] > 0 and t["summary"].startswith("min cell "), (v["probes"], t)
PY
    ;;
  *) echo "unknown case $case_"; exit 2 ;;
esac
echo "ok: $case_"
