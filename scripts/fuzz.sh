#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang (preset "fuzz": coverage + ASan + UBSan) and
# runs each for a bounded time, one after another, through ctest label "fuzz".
#   scripts/fuzz.sh [-t SECONDS] [TARGET...]   default 60 s each, all targets (e.g. codec)
#   scripts/fuzz.sh --seeds                    regenerate fuzz/corpus/ (release preset build)
# Environment: RESOCT_FUZZ_BUILD_DIR (default build/fuzz), RESOCT_JOBS (build jobs, default 2).
# Findings are written to <build dir>/fuzz/artifacts/<target>/; after fixing one, copy it to
# fuzz/regressions/<target>/ so the default test suite replays it (docs/testing.md).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="${RESOCT_JOBS:-2}"
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi

if [ "${1:-}" = "--seeds" ]; then
  cmake --preset release "${launcher[@]}" >/dev/null
  cmake --build --preset release -j "$jobs" --target resoct_fuzz_seeds
  rm -rf fuzz/corpus
  build/release/fuzz/resoct_fuzz_seeds fuzz/corpus
  exit 0
fi

seconds=60
if [ "${1:-}" = "-t" ]; then
  seconds="$2"
  shift 2
fi
if ! command -v clang++ >/dev/null; then
  echo "fuzz.sh: needs clang and libFuzzer (Debian: apt-get install clang libclang-rt-14-dev)" >&2
  exit 1
fi
dir="${RESOCT_FUZZ_BUILD_DIR:-build/fuzz}"
cmake --preset fuzz -B "$dir" -DRESOCT_FUZZ_SECONDS="$seconds" "${launcher[@]}" >/dev/null
cmake --build "$dir" -j "$jobs"
filter=()
if [ $# -gt 0 ]; then
  filter=(-R "^fuzz\.($(IFS='|'; echo "$*"))\$")
fi
status=0
ctest --test-dir "$dir" -L '^fuzz$' "${filter[@]}" -V || status=$?
found=$(find "$dir/fuzz/artifacts" -type f 2>/dev/null | sort)
if [ -n "$found" ]; then
  echo "fuzz.sh: findings (reproduce: <build dir>/fuzz/resoct_fuzz_<target> FILE):"
  echo "$found"
fi
exit $status
