#!/usr/bin/env bash
# Installs every Debian 12 package Terralux needs to build, run and test.
# Idempotent: packages already present are left as they are.
set -euo pipefail

if [ "$(id -u)" -ne 0 ]; then
  echo "install-deps.sh: run as root (it calls apt-get)" >&2
  exit 2
fi

packages=(
  # toolchain
  build-essential cmake ninja-build ccache pkg-config git
  # libraries fixed by the product card
  qt6-base-dev qt6-base-dev-tools libqt6opengl6-dev
  # the study's error-against-time plot (study.png, the Trade-off panel)
  qt6-charts-dev
  libvulkan-dev glslang-tools glslang-dev spirv-tools
  libglm-dev libgdal-dev gdal-bin libopenimageio-dev openimageio-tools
  libtinygltf-dev nlohmann-json3-dev libtbb-dev
  # the sanitize/tsan/fuzz presets: clang, and the sanitizer and libFuzzer runtimes (only
  # recommended by clang-14, and this script installs without recommends)
  clang libclang-rt-14-dev
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
  # bench_tracer's Embree columns (benchmark only; the bench builds without them when absent)
  libembree-dev
  # the project JSON Schema is checked against --print-project with a real validator
  python3 python3-jsonschema
  mesa-vulkan-drivers vulkan-tools vulkan-validationlayers
  xvfb xauth fonts-dejavu-core
  # the Debian packages (cpack -G DEB): icon sizes drawn from the SVG, dependencies from the
  # binaries, and the checks of the package tests (lintian, the desktop entry, AppStream, the
  # MIME database, the manual pages)
  librsvg2-bin dpkg-dev lintian desktop-file-utils appstream shared-mime-info man-db
  # the farm test: a one-node Slurm cluster that the test starts and stops itself
  slurm-wlm munge
  # the glTF validator is an npm package, installed by the test set-up
  nodejs
)
# Debian ships npm as its own package; NodeSource's nodejs already carries it and conflicts.
command -v npm >/dev/null 2>&1 || packages+=(npm)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps.sh: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps.sh: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -q
apt-get install -y -q --no-install-recommends "${missing[@]}"
