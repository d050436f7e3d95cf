#!/usr/bin/env bash
# One sanitizer stage of CI (docs/testing.md "Sanitizers"): scripts/sanitize.sh asan|tsan
# [ctest arguments] configures that preset (clang; ASan + UBSan, or TSan with LLVM's libomp and
# Archer), builds it into build/<preset> and runs the default test suite under it. It fails on a
# failed test and on any sanitizer report, also one from a process whose test passed: every
# report is written to build/<preset>/sanitizer-reports/ (cmake/resoctSanitizers.cmake).
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-}"
case "$preset" in
  asan | tsan) shift ;;
  *)
    echo "usage: scripts/sanitize.sh asan|tsan [ctest arguments]" >&2
    exit 2
    ;;
esac
bash scripts/install-deps.sh
bash scripts/install-test-tools.sh
start=$SECONDS
bash scripts/build.sh "$preset"
echo "sanitize $preset: build took $((SECONDS - start)) s"
# As in scripts/test.sh: a Vulkan or S3 test that would skip for want of its driver or server fails.
export RESOCT_REQUIRE_VULKAN="${RESOCT_REQUIRE_VULKAN:-1}"
export RESOCT_REQUIRE_NPM="${RESOCT_REQUIRE_NPM:-1}"
reports="build/$preset/sanitizer-reports"
rm -rf "$reports"
start=$SECONDS
status=0
ctest --preset "$preset" -j "${RESOCT_JOBS:-2}" "$@" || status=$?
echo "sanitize $preset: tests took $((SECONDS - start)) s"
shopt -s nullglob
found=("$reports"/*)
if [ ${#found[@]} -gt 0 ]; then
  for f in "${found[@]}"; do
    echo "==== $f"
    cat "$f"
  done
  echo "sanitize $preset: ${#found[@]} sanitizer report(s), above" >&2
  status=1
fi
exit "$status"
