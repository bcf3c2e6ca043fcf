#!/usr/bin/env bash
# Installs the Debian 12 packages amalgam needs (idempotent: does nothing when they are all
# present).
#
#   scripts/deps.sh          everything the default build and its tests use: the CLI with
#                            --tracer embree, MPI, the Python module, plots (gnuplot,
#                            matplotlib, pandas), GoogleTest, Google Benchmark, pytest, Jupyter's
#                            nbconvert and IPython kernel (the example notebook), qemu-user
#                            (the portable copy on a CPU without AVX), Debian's Assimp test models
#   scripts/deps.sh --demo   only what scripts/demo.sh needs (the first Quick start command): the
#                            CLI with Embree, the Assimp test models (its herd is Wuson.ply),
#                            matplotlib for the strip
#   scripts/deps.sh --test   everything, plus clang-14 with its sanitizer and libFuzzer runtimes,
#                            which only the sanitizer + fuzzing build (preset asan) uses
set -euo pipefail
mode=${1:-}
case "$mode" in
  "" | --demo | --test) ;;
  *) echo "usage: scripts/deps.sh [--demo | --test]" >&2; exit 2 ;;
esac
packages=(
  build-essential cmake ninja-build pkg-config
  libtbb-dev libpng-dev libjpeg62-turbo-dev libopenexr-dev libstb-dev nlohmann-json3-dev
  libcli11-dev
  libassimp-dev assimp-testmodels libembree-dev
  python3 python3-matplotlib python3-numpy
)
if [ "$mode" != --demo ]; then
  packages+=(
    libgtest-dev libbenchmark-dev gnuplot-nox qemu-user
    pybind11-dev python3-dev python3-pytest python3-pandas jupyter-nbconvert python3-ipykernel
    libopenmpi-dev openmpi-bin
  )
fi
[ "$mode" = --test ] && packages+=(clang-14 libclang-rt-14-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "deps: installing ${missing[*]}" >&2
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi
