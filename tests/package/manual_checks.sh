#!/usr/bin/env bash
# manual_checks.sh TERRALUX_1 TERRALUX_BAKE_1 TERRALUX TERRALUX_BAKE
# The manual pages format without a warning from man (as lintian reads them), and each names
# every option its binary's --help lists.
set -u
fail() { echo "FAIL: $*"; exit 1; }
command -v man >/dev/null || { echo "SKIP: man not installed (man-db)"; exit 77; }
check() {
  local page=$1 binary=$2
  local warnings
  warnings=$(LC_ALL=C.UTF-8 MANWIDTH=80 man --warnings -E UTF-8 -l -Tutf8 -Z "$page" 2>&1 >/dev/null)
  [ -z "$warnings" ] || fail "$page: $warnings"
  local text
  text=$(LC_ALL=C.UTF-8 MANWIDTH=200 man -l "$page" 2>/dev/null | sed 's/.\x08//g')
  local options
  options=$("$binary" --help | grep -Eo '^  --[a-z-]+' | sed 's/^ *//')
  [ -n "$options" ] || fail "$binary --help lists no options"
  for o in $options; do
    grep -Eq -- "^ +$o( |,|$)" <<<"$text" || fail "$page does not describe $o"
  done
  echo "ok: $page ($(wc -w <<<"$options") options)"
}
check "$1" "$3"
check "$2" "$4"
