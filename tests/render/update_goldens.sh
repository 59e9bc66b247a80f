#!/usr/bin/env bash
# Rewrites the golden images of the render tests from the current build, on purpose.
# usage: tests/render/update_goldens.sh [BUILD_DIR]   (default build/release)
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build/release}
TERRALUX_UPDATE_GOLDENS=1 "$build/tests/test_render" --gtest_filter='RenderTest.GoldenImagesOfEveryView'
git status --short tests/render/golden
