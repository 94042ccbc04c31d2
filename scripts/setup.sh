#!/usr/bin/env bash
# Installs every Debian package FeatureMesh needs (skipping what is there), configures and builds
# into build/. Idempotent.
set -euo pipefail
cd "$(dirname "$0")/.."
packages=(cmake g++ make paraview-dev python3-paraview qtbase5-dev qttools5-dev libqt5svg5-dev libqt5x11extras5-dev
  qtxmlpatterns5-dev-tools libutfcpp-dev libdouble-conversion-dev mpi-default-dev libglew-dev libtiff-dev
  libeigen3-dev libcgal-dev libtet1.5-dev libmaxflow-dev libgtest-dev python3-numpy python3-scipy python3-skimage python3-meshio python3-netcdf4 python3-matplotlib python3-nibabel xvfb xauth
  calculix-ccx)
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}"
fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
