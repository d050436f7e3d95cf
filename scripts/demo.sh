#!/usr/bin/env bash
# The README's first command: installs what is missing, builds, and renders the demo: a thin
# 16-channel slab of cell-like blobs (procedural, embedded: nothing is downloaded), 4 channels
# visible, from a cold cache until every needed brick is resident. Output: out/demo.png and
# out/demo-stats.json.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
# Only the renderer and what it links: the tests and benchmarks are built by scripts/test.sh.
bash scripts/build.sh release resoct-render
mkdir -p out
build/release/examples/resoct-render --volume procedural:cells --scene examples/scenes/cells.json \
  --backend cpu --mode residency --converge --width 512 --height 512 \
  --out out/demo.png --stats out/demo-stats.json
echo "demo: wrote out/demo.png and out/demo-stats.json"
