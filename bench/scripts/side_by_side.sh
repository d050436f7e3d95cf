#!/bin/bash
# Side-by-side measurement of a core-library change with one benchmark binary: the same
# resoct_bench_scaling runs alternately against two copies of libresoct_core.so.0 (the build's
# RUNPATH has lower priority than LD_LIBRARY_PATH).
#   bench/scripts/side_by_side.sh BEFORE_LIB_DIR AFTER_LIB_DIR [size_log2 ...]
# e.g. copy build/src/core/libresoct_core.so.0 to /tmp/lib_before before the change and to
# /tmp/lib_after after it, then: bench/scripts/side_by_side.sh /tmp/lib_before /tmp/lib_after 9 11 13
set -euo pipefail
before=$1 after=$2
shift 2
sizes=("$@")
[ ${#sizes[@]} -eq 0 ] && sizes=(9 11 13)
cd "$(dirname "$0")/../.."
for k in "${sizes[@]}"; do
  for v in before after; do
    dir=$before
    [ "$v" = after ] && dir=$after
    out=$(mktemp)
    LD_LIBRARY_PATH=$dir build/bench/resoct_bench_scaling \
      --benchmark_filter="ScreenVsData/size_log2:$k/fixed_leaf:0" --benchmark_format=json \
      2>/dev/null >"$out"
    /usr/bin/python3 - "$out" "$v" "$k" <<'PY'
import json, sys
b = json.load(open(sys.argv[1]))["benchmarks"][0]
print(sys.argv[2], 2 ** int(sys.argv[3]),
      "samples/ray %.1f iterations/ray %.1f ws %d ms_steady %.0f ms_backend %.0f frames %d" % (
          b["samples_per_ray"], b["iterations_per_ray"], b["working_set_bricks"], b["ms_steady"],
          b["ms_last_backend"], b["frames"]))
PY
    rm -f "$out"
  done
done
