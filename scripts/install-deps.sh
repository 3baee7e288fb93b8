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

# apt-get as root, or through sudo; DEBIAN_FRONTEND passed through sudo's
# cleaned environment.
apt() {
  if [ "$(id -u)" -eq 0 ]; then
    DEBIAN_FRONTEND=noninteractive apt-get "$@"
  elif command -v sudo >/dev/null 2>&1; then
    sudo env DEBIAN_FRONTEND=noninteractive apt-get "$@"
  else
    echo "install-deps: these Debian packages are missing and installing them needs root: run this as root" \
         "or install sudo" >&2
    return 1
  fi
}
updated=0
if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}" >&2
  apt update -qq
  updated=1
  apt install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# Data, not a build dependency: the bunny scene's tests skip (saying why)
# without it. node and npm fetch it, any install of them, and none is needed
# once it is here; installing them is not fatal either (a NodeSource nodejs,
# say, conflicts with Debian's npm, and has its own).
bunny="$(dirname "${BASH_SOURCE[0]}")/../scenes/bunny/bunny.obj"
if [ ! -s "$bunny" ] && { ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; }; then
  echo "install-deps: installing nodejs npm (to fetch the bunny)" >&2
  { [ "$updated" -eq 1 ] || apt update -qq; } && apt install -y -qq --no-install-recommends nodejs npm >/dev/null ||
    echo "install-deps: could not install nodejs and npm" >&2
fi
"$(dirname "${BASH_SOURCE[0]}")/fetch-bunny.sh" ||
  echo "install-deps: could not fetch the bunny; run scripts/fetch-bunny.sh later (docs/testing.md)" >&2
