#!/usr/bin/env bash
# Installs what boxplus needs on a Debian machine, only what is missing:
# Ceres 2.1, Eigen, SuiteSparse, CLI11 (boxplus-g2o's options), GoogleTest, clang-format, OpenBLAS (a faster BLAS under
# CHOLMOD than the reference one), a compiler, CMake and Python headers.
set -euo pipefail

pkgs=(g++ make libceres-dev libeigen3-dev libsuitesparse-dev libgtest-dev libgmock-dev libcli11-dev
      libopenblas0-pthread clang-format)
command -v cmake >/dev/null || pkgs+=(cmake)
command -v ninja >/dev/null || pkgs+=(ninja-build)
py_include=$(python3 -c 'import sysconfig; print(sysconfig.get_paths()["include"])' 2>/dev/null || true)
[ -f "${py_include}/Python.h" ] || pkgs+=(python3-dev)
python3 -c 'import ensurepip, venv' 2>/dev/null || pkgs+=(python3-venv)

missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "install_deps: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
