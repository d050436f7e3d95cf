#!/usr/bin/env bash
# Installs the Debian 12 packages resoct needs to build, test (sanitizer stages included) and
# benchmark. Idempotent: when every package is already present it does nothing (and needs no
# network). Runs as root, or via sudo.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config git clang-format
  libglm-dev liblz4-dev libzstd-dev zlib1g-dev libomp-dev
  libvulkan-dev glslang-tools glslang-dev spirv-tools
  mesa-vulkan-drivers vulkan-validationlayers vulkan-tools
  libgtest-dev libgmock-dev libbenchmark-dev
  nlohmann-json3-dev libpng-dev libcli11-dev libcurl4-openssl-dev libblosc-dev libtiff-dev
  python3-matplotlib
  # resoct-view (examples/tools/viewer/): GLFW; its test runs it under a virtual X server
  libglfw3-dev xvfb xauth
  # formats tests: OME-Zarr written by the reference implementation, real MRI volumes
  python3-zarr python3-numcodecs python3-numpy mricron-data
  # HTTP tests and bench_http: /usr/bin/python3 runs tests/support/http_test_server.py
  python3
  # the Python module (python/) and its tests: pybind11 and the headers of Debian's python3
  pybind11-dev python3-dev
  # Sanitizer stages (scripts/sanitize.sh) and the fuzzers: clang, its sanitizer runtimes,
  # llvm-symbolizer for the reports; libomp-dev above brings LLVM's libomp and Archer (TSan)
  clang libclang-rt-14-dev llvm
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# Test-only helpers from the npm registry (scripts/install-test-tools.sh) need node and npm. A
# machine that already has them (Debian's or NodeSource's build) keeps its own.
command -v npm >/dev/null || missing+=(nodejs npm)
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: run as root or install sudo" >&2; exit 1; }
  SUDO="sudo"
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
