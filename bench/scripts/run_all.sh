#!/bin/bash
# Runs the paper-comparison benchmarks and the micro-benchmarks of issue 6 into bench/results and
# regenerates the tables of bench/README.md with report.py. One command for a whole re-run, so the
# published tables always come from one build and one machine state.
#
#   bench/scripts/run_all.sh [--build DIR] [--only "table1 decoupling ..."] [--large]
#
# --build   build directory holding bench/resoct_bench_* (default: build)
# --only    a subset of: table1 decoupling accuracy effects out_of_core scaling limit micro peers
#           (default: all but peers; peers needs python3-vtk9 and xvfb, see bench/README.md)
# --large   the `--large` preset (1024³ class, for machines with ≥ 16 GiB and many cores)
#
# Time on a quiet 2-core VM, standard preset: table1 ~10 min, decoupling ~7 min, accuracy ~4 min,
# effects ~3 min, out_of_core ~15 min, scaling ~10 min, limit ~5 min, micro ~2 min, peers ~1 min.
# Each program's JSON is written to a temporary file first and moved into bench/results only when
# the program succeeded, so an interrupted run never leaves a truncated result behind.
set -euo pipefail
cd "$(dirname "$0")/../.."

build=build
only="table1 decoupling accuracy effects out_of_core scaling limit micro"
large=()
while [ $# -gt 0 ]; do
  case $1 in
    --build) build=$2; shift 2 ;;
    --only) only=$2; shift 2 ;;
    --large) large=(--large); shift ;;
    *) echo "run_all.sh: unknown argument '$1' (see the header of $0)" >&2; exit 2 ;;
  esac
done

results=bench/results
mkdir -p "$results"

# run NAME OUTPUT [benchmark args...]: one program into results/OUTPUT.json via a temporary file.
run() {
  local name=$1 out=$2
  shift 2
  local exe=$build/bench/resoct_bench_$name
  if [ ! -x "$exe" ]; then
    echo "run_all.sh: $exe is missing; build the benchmarks first (scripts/build.sh)" >&2
    exit 1
  fi
  local tmp
  tmp=$(mktemp "$results/.$out.XXXXXX.json")
  echo "== $name -> $results/$out.json ($(date -u +%H:%M:%S), load $(cut -d' ' -f1-3 /proc/loadavg))"
  if "$exe" "$@" "${large[@]}" --benchmark_out="$tmp" --benchmark_out_format=json; then
    mv "$tmp" "$results/$out.json"
  else
    rm -f "$tmp"
    echo "run_all.sh: $name failed; $results/$out.json left unchanged" >&2
    exit 1
  fi
}

for part in $only; do
  case $part in
    table1) run table1 table1 --benchmark_min_time=0.01 ;;
    decoupling) run decoupling decoupling --benchmark_min_time=0.01 ;;
    accuracy) run accuracy accuracy --benchmark_min_time=0.2 ;;
    effects) run effects effects --benchmark_min_time=0.01 ;;
    out_of_core) run out_of_core out_of_core ;;
    scaling) run scaling scaling --benchmark_min_time=0.01 ;;
    limit) run limit limit --benchmark_min_time=2 ;;
    peers)
      # VTK's fixed-point ray caster vs resoct-render on the sphere; writes peer_vtk.json itself
      # (through a temporary file).
      echo "== peers -> $results/peer_vtk.json ($(date -u +%H:%M:%S)," \
        "load $(cut -d' ' -f1-3 /proc/loadavg))"
      /usr/bin/python3 bench/peers/vtk_raycast.py --resoct-render "$build/examples/resoct-render" \
        --out "$results/peer_vtk.json"
      ;;
    micro)
      large=()  # the micro-benchmarks have no presets
      run octree micro_octree --benchmark_filter='BM_Octree(AddEvict|Add|Evict)/16/4/0$' \
        --benchmark_min_time=0.3
      for m in brick_cache request_set page_table traverse; do
        run "$m" "micro_$m" --benchmark_min_time=0.3
      done
      ;;
    *) echo "run_all.sh: unknown part '$part'" >&2; exit 2 ;;
  esac
done

/usr/bin/python3 bench/scripts/report.py
