#!/usr/bin/env bash
# Configures and builds one CMake preset (default: release) into build/<preset>; further
# arguments name the only targets to build (scripts/demo.sh builds resoct-render alone, not the
# tests and benchmarks).
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"
shift || true
jobs="${RESOCT_JOBS:-2}"
cmake --preset "$preset" >/dev/null
if [ "$#" -gt 0 ]; then
  cmake --build --preset "$preset" -j "$jobs" --target "$@"
else
  cmake --build --preset "$preset" -j "$jobs"
fi
