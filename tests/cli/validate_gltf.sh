#!/usr/bin/env bash
# validate_gltf.sh SCENE.gltf [BUILD_DIR]
# Validates SCENE.gltf, with the buffers it references, using the Khronos glTF validator (npm
# package gltf-validator) and prints the error/warning/info/hint counts and every message.
# Exit 0: no errors; 1: errors, or the validator failed; 2: usage; 77: skipped, the validator
# cannot be had (no node or npm, or the npm registry is unreachable).
# The package is installed on first use with `npm install --prefix PREFIX gltf-validator` and reused
# afterwards; PREFIX is $TERRALUX_NPM_PREFIX when set, else BUILD_DIR/gltf-validator.
set -u
here=$(cd "$(dirname "$0")" && pwd)
usage() {
  echo "usage: validate_gltf.sh SCENE.gltf [BUILD_DIR]   (BUILD_DIR or TERRALUX_NPM_PREFIX required)" >&2
  exit 2
}
[ $# -ge 1 ] && [ $# -le 2 ] || usage
scene=$1
if [ -n "${TERRALUX_NPM_PREFIX:-}" ]; then
  prefix=$TERRALUX_NPM_PREFIX
elif [ $# -eq 2 ]; then
  prefix=$2/gltf-validator
else
  usage
fi
[ -f "$scene" ] || { echo "validate_gltf.sh: $scene: no such file" >&2; exit 1; }
command -v node >/dev/null 2>&1 || { echo "SKIP: node not installed: gltf-validator cannot run"; exit 77; }

pkg=$prefix/node_modules/gltf-validator
if [ ! -f "$pkg/package.json" ]; then
  command -v npm >/dev/null 2>&1 || { echo "SKIP: npm not installed: gltf-validator not installed"; exit 77; }
  mkdir -p "$prefix" || exit 1
  # Tests may run in parallel: one installer at a time.
  exec 9>"$prefix/.install.lock"
  if command -v flock >/dev/null 2>&1; then flock 9; fi
  if [ ! -f "$pkg/package.json" ]; then
    log=$prefix/npm-install.log
    echo "installing gltf-validator into $prefix"
    if ! npm install --prefix "$prefix" --no-audit --no-fund --fetch-timeout=20000 \
         --fetch-retries=1 gltf-validator >"$log" 2>&1; then
      if ! timeout 60 npm ping --fetch-timeout=20000 --fetch-retries=0 >/dev/null 2>&1; then
        echo "SKIP: npm registry unreachable: gltf-validator not installed"
        exit 77
      fi
      echo "validate_gltf.sh: npm install gltf-validator failed (log: $log):" >&2
      tail -n 20 "$log" >&2
      exit 1
    fi
  fi
  exec 9>&-
fi
exec node "$here/validate_gltf.mjs" "$pkg" "$scene"
