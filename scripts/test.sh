#!/usr/bin/env bash
# The README's second command: installs what is missing, checks formatting, builds the release
# preset and runs the whole default test suite (opt-in labels "heavy" and "fuzz" excluded).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/check-format.sh
bash scripts/build.sh release
ctest --preset release -j "${RESOCT_JOBS:-2}" "$@"
