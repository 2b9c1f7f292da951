#!/usr/bin/env bash
# Installs the Debian packages bounce needs, only those that are missing.
set -euo pipefail
PKGS=(build-essential cmake pkg-config
      libcgal-dev libopenmesh-dev libglm-dev libvtk9-dev libboost-dev
      libtbb-dev libembree-dev nlohmann-json3-dev libcli11-dev libnanoflann-dev libopenexr-dev
      libgtest-dev libgmock-dev libbenchmark-dev
      python3-vtk9 python3-meshio python3-matplotlib xvfb xauth
      pybind11-dev python3-dev python3-numpy python3-pytest
      clang libclang-rt-14-dev clang-format)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "installing: ${missing[*]}" >&2
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
fi
