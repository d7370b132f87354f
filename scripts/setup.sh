#!/usr/bin/env bash
# Installs the Debian 12 packages vdbdag needs (only what is missing) and
# configures + builds the project in ./build. Safe to run repeatedly.
#
# VDBDAG_BUILD_TARGETS="vdbdag vdbdag_make_samples" builds only those CMake
# targets (what scripts/demo.sh needs first). Unset (the default, and what
# CI uses): every target, tests and benchmarks included.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libopenvdb-dev libnanovdb-dev libboost-iostreams-dev libopenvdb-tools libnanovdb-tools
  libopenimageio-dev openimageio-tools libopenexr-dev libimath-dev
  libvtk9-dev python3-vtk9 libglm-dev
  mesa-vulkan-drivers libvulkan-dev glslc glslang-tools spirv-tools vulkan-tools vulkan-validationlayers
  libtbb-dev libblosc-dev libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev libfmt-dev nlohmann-json3-dev libxxhash-dev libzstd-dev zstd xz-utils
  libzfp-dev fonts-dejavu-core libcharls-dev liblzma-dev libopenjp2-7-dev libfpzip-dev
  libopenmpi-dev openmpi-bin
  libgdcm-dev libgdcm-tools python3-pydicom
  libnifti2-dev python3-nibabel
  libcli11-dev libfmt-dev nlohmann-json3-dev libxxhash-dev libzstd-dev zstd xz-utils zlib1g-dev
  libzfp-dev
  clang libclang-rt-14-dev
  help2man ccache
  pybind11-dev python3-dev python3-numpy python3-pytest python3-openvdb
  # the ParaView plugin (paraview/); pvpython is unpacked, not installed, by scripts/paraview_sdk.sh
  paraview-dev paraview
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${#missing[@]} missing packages: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

BUILD_TYPE=${BUILD_TYPE:-Release}
# VDBDAG_WERROR=ON (scripts/test.sh, so CI): our code's warnings are errors (kept in the cache).
if ! cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE="$BUILD_TYPE" ${VDBDAG_WERROR:+-DVDBDAG_WERROR=$VDBDAG_WERROR} > build.configure.log 2>&1; then
  cat build.configure.log; exit 1
fi
TARGETS=${VDBDAG_BUILD_TARGETS:-}
if [ -n "$TARGETS" ]; then
  read -r -a target_list <<< "$TARGETS"
  cmake --build build -j"$(nproc)" --target "${target_list[@]}"
else
  cmake --build build -j"$(nproc)"
fi
