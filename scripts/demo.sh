#!/usr/bin/env bash
# The README's first command: installs what is missing, builds, and runs the demo on an embedded
# procedural dataset. Output goes to out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh release
mkdir -p out
bin=build/release/examples
"$bin/resoct-convert" procedural:cells:256x256x40:16 out/demo-cells.rbs --codec zstd
"$bin/resoct-info" out/demo-cells.rbs
