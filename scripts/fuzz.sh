#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang (preset "fuzz": coverage + ASan + UBSan) and
# runs each for a bounded time, one after another, through ctest label "fuzz".
#   scripts/fuzz.sh [-t SECONDS] [-n RUNS] [--keep] [TARGET...]
#       default 60 s each, all targets (e.g. codec). -n stops each target after RUNS executions
#       (then -t, default one day with -n, is only a cap). --keep merges what each target's
#       working corpus gained into fuzz/grown/<target>/ (libFuzzer -merge=1: only inputs that add
#       coverage, smallest first), which the default test suite replays.
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

seconds=""
runs=0
keep=0
while [ $# -gt 0 ]; do
  case "$1" in
    -t) seconds="$2"; shift 2 ;;
    -n) runs="$2"; shift 2 ;;
    --keep) keep=1; shift ;;
    *) break ;;
  esac
done
if [ -z "$seconds" ]; then
  if [ "$runs" -gt 0 ]; then seconds=86400; else seconds=60; fi
fi
if ! command -v clang++ >/dev/null; then
  echo "fuzz.sh: needs clang and libFuzzer (Debian: apt-get install clang libclang-rt-14-dev)" >&2
  exit 1
fi
dir="${RESOCT_FUZZ_BUILD_DIR:-build/fuzz}"
cmake --preset fuzz -B "$dir" -DRESOCT_FUZZ_SECONDS="$seconds" -DRESOCT_FUZZ_RUNS="$runs" \
  "${launcher[@]}" >/dev/null
cmake --build "$dir" -j "$jobs"
filter=()
if [ $# -gt 0 ]; then
  filter=(-R "^fuzz\.($(IFS='|'; echo "$*"))\$")
fi
status=0
ctest --test-dir "$dir" -L '^fuzz$' "${filter[@]}" -V || status=$?
if [ "$keep" = 1 ]; then
  for work in "$dir"/fuzz/corpus/*/; do
    name=$(basename "$work")
    [ $# -gt 0 ] && [[ " $* " != *" $name "* ]] && continue
    mkdir -p "fuzz/grown/$name"
    # libFuzzer's merge: an input of the working corpus joins grown/ only if it adds coverage
    # beyond what grown/ already holds.
    "$dir/fuzz/resoct_fuzz_$name" -merge=1 -rss_limit_mb=2048 -timeout=10 "fuzz/grown/$name" \
      "$work" 2>&1 | grep -E "MERGE-OUTER: [0-9]+ new files" || true
    rmdir --ignore-fail-on-non-empty "fuzz/grown/$name"
  done
fi
found=$(find "$dir/fuzz/artifacts" -type f 2>/dev/null | sort)
if [ -n "$found" ]; then
  echo "fuzz.sh: findings (reproduce: <build dir>/fuzz/resoct_fuzz_<target> FILE):"
  echo "$found"
fi
exit $status
