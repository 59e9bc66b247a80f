#!/bin/sh
# run_fuzz.sh FUZZER SECONDS WORKDIR DICT CORPUS [REGRESSIONS]
# Runs one libFuzzer target for SECONDS ("env": $TERRALUX_FUZZ_SECONDS, default 300; "smoke": 20) over its
# committed corpus and regression inputs. New inputs go to WORKDIR/corpus (libFuzzer writes to
# its first corpus folder), crash, leak, timeout and OOM inputs to WORKDIR/artifacts. Limits:
# 1 s per input ($TERRALUX_FUZZ_INPUT_SECONDS where a target sets more), 2 GiB resident and per
# allocation. The 20-second smoke runs of the sanitize preset share two cores with the rest of the
# suite, where an input that takes 0.8 s alone can take twice that: they allow at least 5 s, so
# only a real hang fails them. Smoke runs use a fixed seed, so a change is judged on the same
# mutations every time and CI does not fail on what one random draw happened to reach; the long
# runs draw a new seed each time.
set -eu
fuzzer=$1 seconds=$2 work=$3 dict=$4 corpus=$5
regressions=${6:-}
timeout=${TERRALUX_FUZZ_INPUT_SECONDS:-1}
[ "$seconds" = env ] && seconds=${TERRALUX_FUZZ_SECONDS:-300}
seed=0
if [ "$seconds" = smoke ]; then
  seconds=20
  seed=1
  [ "$timeout" -lt 5 ] && timeout=5
fi
mkdir -p "$work/corpus" "$work/artifacts"
set -- -seed="$seed" -max_total_time="$seconds" -timeout="$timeout" -rss_limit_mb=2048 -malloc_limit_mb=2048 \
  -print_final_stats=1 -artifact_prefix="$work/artifacts/" "$work/corpus" "$corpus"
[ -n "$dict" ] && set -- -dict="$dict" "$@"
[ -n "$regressions" ] && [ -d "$regressions" ] && set -- "$@" "$regressions"
exec "$fuzzer" "$@"
