#!/usr/bin/env bash
# sampling_target_checks.sh CASE TERRALUX WORKDIR DEM
# bake.target_error end to end on a committed DEM crop: the bake chooses rays and bounces, says
# what it replaced, and meets the target on its own probes' standard error; the dry run makes the
# same choice and writes nothing; the reference preset refuses a target in one line.
set -u
case_=$1 terralux=$2 work=$3 dem=$4
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }
line='^  bake.target_error 1.0 %: [0-9 ]+ rays \(p95 standard error [0-9.]+ %\), [0-9]+ bounces? \(one more adds [0-9.]+ %\)'
case "$case_" in
  meets)
    "$terralux" --bake --quiet --dem "$dem" --out "$work/out" --set bake.rays=32 \
      --set bake.target_error=0.01 >"$work/stdout" 2>"$work/stderr" || fail "bake exited $?"
    python3 - "$work/out/bake_report.json" <<'PY' || fail "bake_report.json"
import json, sys
r = json.load(open(sys.argv[1]))
t, q = r["sampling_target"], r["quality"]
assert t["target"] == 0.01 and t["met"] is True, t
assert q["rays"] == t["rays"] and q["bounces"] == t["bounces"], (q, t)
assert t["rays"] > 32 and t["rays"] & (t["rays"] - 1) == 0, t
assert t["replaced"] == "bake.rays 32 and 2 bounces", t
assert t["baked_standard_error_p95"] <= 0.01, t
assert t["baked_standard_error_p95"] == max(v["standard_error"]["p95"] for v in r["volumes"]), t
assert t["next_bounce_change_p95"] < 0.01 and t["bounce_trials"][-1]["bounces"] == t["bounces"], t
assert r["volumes"][0]["rays"] >= r["volumes"][0]["probes"] * t["rays"], r["volumes"][0]
assert r["inputs"]["settings"]["bake"]["target_error"] == 0.01, r["inputs"]["settings"]["bake"]
PY
    grep -Eq "$line \(replaces bake.rays 32 and 2 bounces\); the baked probes' p95 standard error is [0-9.]+ % \(meets it\)$" \
      "$work/stdout" || fail "stdout does not explain the choice: $(cat "$work/stdout")"
    [ -s "$work/stderr" ] && fail "stderr not empty: $(cat "$work/stderr")"
    ;;
  dry_run)
    "$terralux" --bake --dry-run --quiet --dem "$dem" --out "$work/out" \
      --set bake.target_error=0.01 >"$work/stdout" 2>"$work/stderr" || fail "dry run exited $?"
    grep -Eq "^dry run: nothing baked, nothing written \(standard, [0-9]+ rays, [0-9]+ bounces" "$work/stdout" \
      || fail "no dry-run header"
    grep -Eq "$line on 64 probes \(replaces the standard preset's 0\.40 % standard error per probe \(256 to 16384 rays\) and 2 bounces; meets it; [0-9]+ trials" \
      "$work/stdout" || fail "no choice in the dry run: $(cat "$work/stdout")"
    [ -e "$work/out" ] && fail "the dry run created $work/out"
    [ -s "$work/stderr" ] && fail "stderr not empty"
    ;;
  reference)
    "$terralux" --bake --quiet --quality reference --dem "$dem" --out "$work/out" \
      --set bake.target_error=0.01 >"$work/stdout" 2>"$work/stderr"
    rc=$?
    [ "$rc" = 2 ] || fail "want exit 2, got $rc"
    [ "$(wc -l <"$work/stderr")" = 1 ] || fail "want one stderr line: $(cat "$work/stderr")"
    grep -Eq "^terralux: bake.target_error = 0.01: the reference preset path-traces every bounce to convergence" \
      "$work/stderr" || fail "no plain refusal: $(cat "$work/stderr")"
    [ -e "$work/out/bake_report.json" ] && fail "a refused bake wrote a report"
    ;;
  *) echo "unknown case $case_"; exit 2 ;;
esac
echo "ok: $case_"
