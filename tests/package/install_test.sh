#!/usr/bin/env bash
# install_test.sh BUILD_DIR WORKDIR
# Builds the two Debian packages from BUILD_DIR with cpack, checks them with lintian, installs them
# with apt-get (so their dependencies resolve as a user's would), runs the installed terralux-bake
# --bake and terralux --render on the embedded sample from an empty folder with nothing of the
# build on PATH or LD_LIBRARY_PATH, checks what they wrote, and removes the packages again: the
# machine's package set is compared before and after.
set -u -o pipefail
build=$(cd "$1" && pwd) work=$2
fail() { echo "FAIL: $*"; exit 1; }
if [ "$(id -u)" -ne 0 ]; then echo "SKIP: the install test installs packages: run it as root"; exit 77; fi
for tool in cpack apt-get dpkg-deb dpkg-query lintian; do
  command -v $tool >/dev/null || { echo "SKIP: $tool not installed (packaging/install-deps.sh installs it)"; exit 77; }
done
state() { dpkg-query -W -f='${binary:Package} ${Version} ${db:Status-Abbrev}\n' | sort; }
if dpkg-query -W -f='${db:Status-Abbrev}\n' terralux terralux-bake 2>/dev/null | grep -q '^.i'; then
  fail "terralux is installed on this machine already; the test would replace it (apt-get purge terralux terralux-bake)"
fi
t0=$(date +%s.%N)
rm -rf "$work" && mkdir -p "$work/debs" "$work/run" "$work/reference"
before=$(state)

# 1. Build.
cpack --config "$build/CPackConfig.cmake" -B "$work/debs" >"$work/cpack.log" 2>&1 ||
  fail "cpack: $(tail -5 "$work/cpack.log")"
bake_deb=$(ls "$work"/debs/terralux-bake_*.deb) app_deb=$(ls "$work"/debs/terralux_*.deb) ||
  fail "cpack wrote $(ls "$work/debs")"
t1=$(date +%s.%N)

# 2. lintian: no error and no warning.
lintian --fail-on error,warning "$bake_deb" "$app_deb" >"$work/lintian.log" 2>&1 ||
  fail "lintian: $(grep -E '^(E|W):' "$work/lintian.log" | head -20)"
t2=$(date +%s.%N)

# 3. The headless package depends on no GUI module and no Vulkan loader; the authoring one on the
#    headless one of the same version.
bake_depends=$(dpkg-deb -f "$bake_deb" Depends)
! grep -Eiq 'vulkan|qt6gui|qt6widgets|qt6charts|qt6opengl|qpa' <<<"$bake_depends" ||
  fail "terralux-bake depends on a GUI or GPU package: $bake_depends"
version=$(dpkg-deb -f "$app_deb" Version)
grep -q "terralux-bake (= $version)" <<<"$(dpkg-deb -f "$app_deb" Depends)" ||
  fail "terralux does not depend on terralux-bake (= $version)"

# 4. Install; whatever happens next, remove them again.
newly_installed() { comm -13 <(echo "$before" | awk '{print $1}' | sort -u) <(state | awk '{print $1}' | sort -u); }
cleanup() {
  local extra
  extra=$(newly_installed | tr '\n' ' ')
  [ -n "$extra" ] && DEBIAN_FRONTEND=noninteractive apt-get purge -y -q $extra >>"$work/apt.log" 2>&1
}
trap cleanup EXIT
DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "$bake_deb" "$app_deb" \
  >"$work/apt.log" 2>&1 || fail "apt-get install: $(tail -5 "$work/apt.log")"
t3=$(date +%s.%N)
# What each package brings onto a bare machine: every package it needs, recursively.
closure() { apt-cache depends --recurse --no-recommends --no-suggests --no-conflicts --no-breaks --no-replaces \
              --no-enhances "$1" 2>/dev/null | grep -E '^[a-z0-9]' | sort -u | wc -l; }
bake_closure=$(closure terralux-bake) app_closure=$(closure terralux)
[ "$(command -v terralux-bake)" = /usr/bin/terralux-bake ] || fail "terralux-bake is not /usr/bin/terralux-bake"
for f in /usr/share/man/man1/terralux.1.gz /usr/share/man/man1/terralux-bake.1.gz \
         /usr/share/applications/org.terralux.Terralux.desktop /usr/share/metainfo/org.terralux.Terralux.metainfo.xml \
         /usr/share/icons/hicolor/scalable/apps/org.terralux.Terralux.svg /usr/share/icons/hicolor/48x48/apps/org.terralux.Terralux.png \
         /usr/share/terralux/terralux.schema.json /usr/share/doc/terralux/formats.md /usr/share/doc/terralux-bake/copyright; do
  [ -s "$f" ] || fail "$f is not installed"
done
if [ -f /usr/share/mime/globs2 ]; then
  grep -q 'application/x-terralux-project:\*\.terralux\.json' /usr/share/mime/globs2 ||
    fail "the MIME database does not know *.terralux.json after the install"
fi

# 5. Run the installed binaries from an empty folder, with a clean environment.
run() { (cd "$work/run" && env -i HOME="$work/run" PATH=/usr/bin:/bin LANG=C.UTF-8 "$@"); }
run terralux-bake --version | grep -qx "terralux-bake $version" || fail "terralux-bake --version is not $version"
run terralux-bake --bake --quiet >"$work/bake.out" 2>"$work/bake.err" ||
  fail "terralux-bake --bake: $(cat "$work/bake.err")"
for f in scene.gltf scene.bin bake_report.json; do
  [ -s "$work/run/bake/$f" ] || fail "terralux-bake --bake wrote no bake/$f"
done
probes=$(cd "$work/run/bake" && find . -name '*.shprobe' | wc -l)
[ "$probes" -ge 1 ] || fail "terralux-bake --bake wrote no .shprobe"
# The installed binary bakes the same bytes as the one in the build tree.
(cd "$work/reference" && "$build/app/terralux-bake" --bake --quiet >/dev/null 2>&1) || fail "the build tree's bake failed"
for f in $(cd "$work/reference/bake" && find . -name '*.shprobe'); do
  cmp -s "$work/reference/bake/$f" "$work/run/bake/$f" || fail "$f differs from the build tree's bake"
done
run terralux --render --quiet --size 320x180 --out frame.png >"$work/render.out" 2>"$work/render.err" ||
  fail "terralux --render: $(cat "$work/render.err")"
grep -q '^rendered .*frame.png (320x180, view 0 beauty, 1 probe volume' "$work/render.out" ||
  fail "terralux --render said: $(cat "$work/render.out")"
[ "$(head -c 4 "$work/run/frame.png" | od -An -c | tr -d ' ')" = "211PNG" ] || fail "frame.png is not a PNG"
[ "$(stat -c %s "$work/run/frame.png")" -gt 20000 ] || fail "frame.png is $(stat -c %s "$work/run/frame.png") bytes: an empty frame?"
t4=$(date +%s.%N)

# 6. Remove; the package set is as it was.
trap - EXIT
cleanup
after=$(state)
[ "$before" = "$after" ] || fail "the machine's packages differ after the purge: $(diff <(echo "$before") <(echo "$after") | head)"
t5=$(date +%s.%N)

size() { stat -c %s "$1"; }
secs() { awk "BEGIN { printf \"%.1f\", $1 - $2 }"; }
echo "ok: terralux-bake $(size "$bake_deb") bytes, terralux $(size "$app_deb") bytes"
echo "ok: depends: terralux-bake $(tr ',' '\n' <<<"$bake_depends" | wc -l) direct, $bake_closure recursively;" \
     "terralux $(dpkg-deb -f "$app_deb" Depends | tr ',' '\n' | wc -l) direct, $app_closure recursively"
echo "ok: cpack $(secs $t1 $t0) s, lintian $(secs $t2 $t1) s, install $(secs $t3 $t2) s, run $(secs $t4 $t3) s," \
     "purge $(secs $t5 $t4) s, total $(secs $t5 $t0) s"
