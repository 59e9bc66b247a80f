#!/usr/bin/env bash
# expect.sh CODE STDERR_REGEX STDOUT_REGEX -- COMMAND...
# Runs COMMAND and checks its exit code, that stderr matches STDERR_REGEX (extended regex; "" =
# must be empty, "*" = anything) and that stdout matches STDOUT_REGEX ("" = anything). Error output must be one
# line, plus the "Try 'terralux --help'." (or terralux-bake) hint for usage errors.
set -u
code=$1 errRe=$2 outRe=$3
shift 4
out=$(mktemp) err=$(mktemp)
trap 'rm -f "$out" "$err"' EXIT
"$@" >"$out" 2>"$err"
rc=$?
fail() { echo "FAIL: $*"; echo "--- command: $*"; echo "--- stdout:"; head -c 3000 "$out"; echo "--- stderr:"; cat "$err"; exit 1; }
[ "$rc" -eq "$code" ] || fail "exit code $rc, expected $code"
if [ "$errRe" = "*" ]; then
  :
elif [ -z "$errRe" ]; then
  [ ! -s "$err" ] || fail "stderr not empty"
else
  grep -Eq -- "$errRe" "$err" || fail "stderr does not match /$errRe/"
  if [ "$code" -ne 0 ]; then
    lines=$(grep -Evc "^Try 'terralux(-bake)? --help'.$" "$err")
    [ "$lines" -eq 1 ] || fail "error is $lines lines, expected one"
  fi
fi
if [ -n "$outRe" ]; then
  grep -Eq -- "$outRe" "$out" || fail "stdout does not match /$outRe/"
fi
echo "ok: exit $rc"
