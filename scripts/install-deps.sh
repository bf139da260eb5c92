#!/usr/bin/env bash
# Installs every Debian package saarcor-model needs, and nothing when they are all there.
# Idempotent: safe to run before every build (the README's two commands do).
set -euo pipefail

packages=(
  cmake g++ ninja-build pkg-config git
  libglm-dev libtinygltf-dev libstb-dev nlohmann-json3-dev
  libopenimageio-dev openimageio-tools libopencv-core-dev
  libgtest-dev libgmock-dev libbenchmark-dev libcli11-dev
  libmpfr-dev libembree-dev
  libsystemc-dev
  verilator yosys
  python3-matplotlib libopenmpi-dev openmpi-bin
  clang libclang-rt-14-dev llvm
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
