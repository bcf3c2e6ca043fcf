#!/usr/bin/env bash
# Installs the Debian 12 packages amalgam needs to build, test and plot (idempotent: does
# nothing when they are all present). With --test, also clang-14 and its sanitizer and libFuzzer
# runtimes, which only the sanitizer + fuzzing build (preset asan) uses.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config
  libtbb-dev libpng-dev libjpeg62-turbo-dev libopenexr-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libbenchmark-dev
  libassimp-dev assimp-testmodels
  libembree-dev
  gnuplot-nox python3 python3-matplotlib python3-numpy qemu-user
  pybind11-dev python3-dev python3-pytest python3-pandas
  libopenmpi-dev openmpi-bin
)
[ "${1:-}" = --test ] && packages+=(clang-14 libclang-rt-14-dev)
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
