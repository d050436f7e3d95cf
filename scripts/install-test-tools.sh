#!/usr/bin/env bash
# Installs the test-only helpers from the npm registry into tests/npm/node_modules, exactly as
# tests/npm/package-lock.json pins them: zarrita (validates the Zarr v3 fixtures) and s3rver (the
# S3-compatible server of the object-store tests). Idempotent: does nothing when the installed
# tree matches the lock file. Needs node and npm (install-deps.sh installs them when missing).
set -euo pipefail
cd "$(dirname "$0")/../tests/npm"
stamp=node_modules/.resoct-lock.sha256
want=$(sha256sum package-lock.json | cut -d' ' -f1)
if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
  echo "install-test-tools: up to date"
  exit 0
fi
npm ci --no-audit --no-fund --loglevel=error
echo "$want" >"$stamp"
echo "install-test-tools: installed $(ls node_modules | wc -l) packages"
