#!/usr/bin/env bash
# desktop_checks.sh DESKTOP METAINFO MIME WORKDIR
# The desktop entry and the AppStream metadata pass their validators with nothing to say, and the
# MIME type makes *.terralux.json a Terralux project in a real shared-mime-info database.
set -u
desktop=$1 metainfo=$2 mime=$3 work=$4
fail() { echo "FAIL: $*"; exit 1; }
for tool in desktop-file-validate appstreamcli update-mime-database; do
  command -v $tool >/dev/null || { echo "SKIP: $tool not installed (packaging/install-deps.sh installs it)"; exit 77; }
done

out=$(desktop-file-validate "$desktop" 2>&1) || fail "desktop-file-validate: $out"
[ -z "$out" ] || fail "desktop-file-validate has remarks: $out"
echo "ok: $desktop"

out=$(appstreamcli validate --no-net "$metainfo" 2>&1) || fail "appstreamcli validate: $out"
! grep -Eq '^(E|W|I):' <<<"$out" || fail "appstreamcli validate has remarks: $out"
echo "ok: $metainfo"

rm -rf "$work" && mkdir -p "$work/packages"
cp "$mime" "$work/packages/"
update-mime-database "$work" || fail "update-mime-database refused $mime"
grep -q '^60:application/x-terralux-project:\*\.terralux\.json$' "$work/globs2" ||
  fail "no *.terralux.json glob in the database: $(cat "$work/globs2")"
grep -q '^application/x-terralux-project application/json$' "$work/subclasses" ||
  fail "the project type is not a kind of application/json"
echo "ok: $mime"
