#!/usr/bin/env bash
# Configures and builds one CMake preset (default: release) into build/<preset>.
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"
jobs="${RESOCT_JOBS:-2}"
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset" -j "$jobs"
