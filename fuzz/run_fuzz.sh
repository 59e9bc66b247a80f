#!/bin/sh
# run_fuzz.sh FUZZER SECONDS WORKDIR DICT CORPUS [REGRESSIONS]
# Runs one libFuzzer target for SECONDS ("env": $TERRALUX_FUZZ_SECONDS, default 300; "smoke": see
# below) over its
# committed corpus and regression inputs. New inputs go to WORKDIR/corpus (libFuzzer writes to
# its first corpus folder), crash, leak, timeout and OOM inputs to WORKDIR/artifacts. Limits:
# 1 s per input ($TERRALUX_FUZZ_INPUT_SECONDS where a target sets more), 2 GiB resident and per
# allocation. The smoke runs of the sanitize preset share two cores with the rest of the suite,
# where an input that takes 0.8 s alone can take twice that: they allow at least 5 s, so only a
# real hang fails them. A smoke run tries $TERRALUX_FUZZ_SMOKE_RUNS inputs (set per target by
# fuzz/CMakeLists.txt) from a fixed seed, starting from the committed corpus alone (the previous
# run's finds are cleared): every machine tries the same inputs in the same order, so what CI
# finds, a local `ctest --preset sanitize` finds first. $TERRALUX_FUZZ_SMOKE_SECONDS (default 120)
# only caps a machine too slow to finish them. The long runs keep their finds and draw a new seed
# each time.
#
# libFuzzer's log goes to WORKDIR/fuzz.log. A CI log keeps only the end of a failed test's output,
# so on failure this prints the lines that say why (the sanitizer or libFuzzer report), the log's
# last lines and every finding's input in base64, enough to commit it as a regression input
# without the build tree. A run that ended on a signal from outside (no report, no finding: the
# machine's OOM killer, say) says so and runs once more; a finding never does.
set -eu
fuzzer=$1 seconds=$2 work=$3 dict=$4 corpus=$5
regressions=${6:-}
timeout=${TERRALUX_FUZZ_INPUT_SECONDS:-1}
[ "$seconds" = env ] && seconds=${TERRALUX_FUZZ_SECONDS:-300}
seed=0
runs=-1
if [ "$seconds" = smoke ]; then
  seconds=${TERRALUX_FUZZ_SMOKE_SECONDS:-120}
  runs=${TERRALUX_FUZZ_SMOKE_RUNS:--1}
  seed=1
  [ "$timeout" -lt 5 ] && timeout=5
  rm -rf "$work/corpus"
fi
mkdir -p "$work/corpus" "$work/artifacts"
set -- -seed="$seed" -runs="$runs" -max_total_time="$seconds" -timeout="$timeout" -rss_limit_mb=2048 -malloc_limit_mb=2048 \
  -print_final_stats=1 -artifact_prefix="$work/artifacts/" "$work/corpus" "$corpus"
[ -n "$dict" ] && set -- -dict="$dict" "$@"
[ -n "$regressions" ] && [ -d "$regressions" ] && set -- "$@" "$regressions"
log=$work/fuzz.log
name=$(basename "$fuzzer")

marker=$work/.started
findings() { find "$work/artifacts" -type f -newer "$marker" | sort; }

attempt=1
while :; do
  touch "$marker"
  status=0
  "$fuzzer" "$@" > "$log" 2>&1 || status=$?
  if [ "$status" -eq 0 ]; then
    grep -E '^(Done|stat::)' "$log" || true
    echo "$name: no finding (log: $log)"
    exit 0
  fi
  new=$(findings | wc -l)
  report=$(grep -E 'ERROR: |ALARM: |SUMMARY: |runtime error: |Test unit written|deadly signal|out-of-memory|==[0-9]+==' "$log" | head -n 20 || true)
  if [ "$status" -gt 128 ] && [ "$new" -eq 0 ] && [ -z "$report" ] && [ "$attempt" -eq 1 ]; then
    echo "$name: stopped by signal $((status - 128)) with no report and no finding; running it once more"
    tail -n 5 "$log"
    attempt=2
    continue
  fi
  break
done

echo "$name: FAILED, exit status $status (log: $log)"
[ -n "$report" ] && { echo "--- why"; echo "$report"; }
echo "--- last lines"
tail -n 25 "$log"
for f in $(findings); do
  echo "--- finding $(basename "$f"), $(wc -c < "$f") bytes, base64 (decode with: base64 -d > input):"
  head -c 8192 "$f" | base64
done
exit "$status"
