#!/usr/bin/env bash
# Installs the Debian packages the build, the tests and the benchmarks need.
# Idempotent and quiet: when everything is present it prints nothing and exits 0.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libvulkan-volk-dev libvulkan-dev
  glslang-tools glslang-dev spirv-tools
  mesa-vulkan-drivers vulkan-validationlayers
  libglm-dev libtinyobjloader-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  nlohmann-json3-dev libcli11-dev
  libstb-dev libtinyexr-dev libtinygltf-dev zlib1g-dev
  python3 python3-numpy python3-matplotlib
  clang libclang-rt-14-dev
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# node and npm fetch the bunny; any install of them will do, and none is
# needed once it is here.
bunny="$(dirname "${BASH_SOURCE[0]}")/../scenes/bunny/bunny.obj"
if [ ! -s "$bunny" ] && { ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; }; then
  missing+=(nodejs npm)
fi

if [ ${#missing[@]} -gt 0 ]; then
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  echo "install-deps: installing ${missing[*]}" >&2
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# Data, not a build dependency: the bunny scene's tests skip (saying why) without it.
"$(dirname "${BASH_SOURCE[0]}")/fetch-bunny.sh" ||
  echo "install-deps: could not fetch the bunny; run scripts/fetch-bunny.sh later" >&2
