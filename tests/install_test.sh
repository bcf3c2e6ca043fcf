#!/usr/bin/env bash
# `cmake --install` gives a usable package: a consumer program configured with only
# find_package(amalgam) builds against the installed headers and libraries, gets none of our
# build flags (warnings, -Werror, ISA defines), and renders exactly what the CLI renders.
# Usage: install_test.sh BUILD_DIR SOURCE_DIR [CXX_FLAGS LINKER_FLAGS]
# The flags are the build's own sanitizer flags, if any: a library built with ASan links only
# into a program built with it (the consumer gets exactly these, nothing else of ours).
set -euo pipefail
build=$1 src=$2 cxx_flags=${3:-} link_flags=${4:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
for f in bin/amalgam bin/amalgam-import share/amalgam/scenes/field.json \
         include/amalgam/render/render.h \
         include/amalgam/render/render_isa.inl lib/cmake/amalgam/amalgamConfig.cmake; do
  [ -e "$tmp/prefix/$f" ] || { echo "not installed: $f"; exit 1; }
done
unset CXXFLAGS CMAKE_CXX_COMPILER_LAUNCHER
cmake -S "$src/tests/install/consumer" -B "$tmp/consumer" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$tmp/prefix" -DCMAKE_EXPORT_COMPILE_COMMANDS=ON \
  -DCMAKE_CXX_FLAGS="$cxx_flags" -DCMAKE_EXE_LINKER_FLAGS="$link_flags" >/dev/null
cmake --build "$tmp/consumer" >/dev/null
if grep -E -- '-Werror|-Wpedantic|-mavx|AMALGAM_BUILD_AVX2_COPY|AMALGAM_IMPORT_HELPER' \
     "$tmp/consumer/compile_commands.json"; then
  echo "build flags of amalgam leaked into the consumer"; exit 1
fi
if grep -q -- "$src/src" "$tmp/consumer/compile_commands.json"; then
  echo "the consumer includes from the source tree, not the installed headers"; exit 1
fi
# Everything below runs as it would once the build tree is deleted: in a mount namespace
# where an empty directory hides it, and with no AMALGAM_IMPORT_HELPER, so the installed
# programs must find the installed importer themselves (io/mesh_import.h).
unset AMALGAM_IMPORT_HELPER
mkdir "$tmp/empty"
hidden() { unshare --map-root-user --mount bash -c 'mount --bind "$1" "$2" && shift 2 && "$@"' \
             hidden "$tmp/empty" "$(realpath "$build")" "$@"; }
[ -z "$(hidden ls -A "$build")" ] || { echo "the build tree is still visible"; exit 1; }
for scene in builtin:line /usr/share/assimp/models/PLY/Wuson.ply; do
  line=$(hidden "$tmp/consumer/consumer" "$scene")
  echo "$line"
  tests=$(sed -E 's/.* ([0-9]+) tests.*/\1/' <<<"$line")
  cli=$(hidden "$tmp/prefix/bin/amalgam" render "$scene" --width 32 --height 24 --spp 2 \
          --threads 1 --out "$tmp/cli.pfm" --stats - --quiet |
        python3 -c 'import json,sys; print(json.load(sys.stdin)["tests"]["total"])')
  [ "$tests" = "$cli" ] || { echo "$scene: consumer counted $tests tests, the CLI $cli"; exit 1; }
done
# The Python module, when the build has one: installed, imported from the prefix, and able to
# import a mesh with the build tree gone.
if compgen -G "$build/python/amalgam*.so" >/dev/null; then
  module=$(compgen -G "$tmp/prefix/lib/python3/dist-packages/amalgam*.so") ||
    { echo "not installed: the Python module"; exit 1; }
  hidden env PYTHONPATH="$(dirname "$module")" /usr/bin/python3 -c '
import sys, amalgam
assert amalgam.__file__ == sys.argv[1], amalgam.__file__
s = amalgam.load("/usr/share/assimp/models/PLY/Wuson.ply")
r = s.render(width=16, height=12, spp=1, threads=1)
print("python: Wuson", r.stats["tests"]["total"], "tests")' "$module"
fi
echo "install ok"
