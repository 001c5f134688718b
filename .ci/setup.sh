#!/usr/bin/env bash
# Installs hexrefine's build, test and plotting dependencies from Debian's packages (idempotent);
# clang-14 and libclang-rt-14-dev (libFuzzer, ASan, UBSan) build the reader fuzz targets;
# pybind11-dev, python3-dev, python3-numpy and python3-pytest build and test the Python module;
# python3-jsonschema validates reports and records against docs/schema/.
# universal-ctags measures function lengths for .ci/function_lengths.py.
# valgrind counts the instructions of the performance gate (hexrefine bench --instructions).
# python3-dolfinx solves the adaptive loop's Poisson problems (experiments/adaptive).
set -euo pipefail
packages=(cmake g++ make clang-format libeigen3-dev libopenmesh-dev nlohmann-json3-dev libgtest-dev
          libbenchmark-dev libexodusii-dev python3-meshio python3-vtk9 python3-matplotlib gmsh
          clang-14 libclang-rt-14-dev pybind11-dev python3-dev python3-numpy python3-pytest
          python3-jsonschema zlib1g-dev valgrind universal-ctags
          python3-dolfinx)
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}"
fi
