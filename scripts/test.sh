#!/usr/bin/env bash
# The README's second command: installs what is missing (Debian packages, then the npm test
# helpers), checks formatting, builds the release preset and runs the whole default test suite
# (opt-in labels "heavy" and "fuzz" excluded).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/install-test-tools.sh
bash scripts/check-format.sh
# install-deps.sh installs pybind11, the Python headers and numpy, so the Python module must be
# built (and its tests run): configuring fails rather than leaving it out. RESOCT_REQUIRE_PYTHON=0
# opts out.
export RESOCT_REQUIRE_PYTHON="${RESOCT_REQUIRE_PYTHON:-1}"
bash scripts/build.sh release
# install-deps.sh installs lavapipe, so Vulkan must work here: a Vulkan test that would skip for
# want of a driver fails instead (docs/testing.md). RESOCT_REQUIRE_VULKAN=0 opts out.
export RESOCT_REQUIRE_VULKAN="${RESOCT_REQUIRE_VULKAN:-1}"
# Likewise the npm test tools installed above (the S3 tests' s3rver): their tests fail rather than
# skip when the tools are missing. RESOCT_REQUIRE_NPM=0 opts out.
export RESOCT_REQUIRE_NPM="${RESOCT_REQUIRE_NPM:-1}"
ctest --preset release -j "${RESOCT_JOBS:-2}" "$@"
