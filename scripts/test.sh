#!/usr/bin/env bash
# Quick start, command 2: install what is missing, build, run every test.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
cmake --preset release >/dev/null
cmake --build --preset release
ctest --preset release

# The same suite under AddressSanitizer + UndefinedBehaviorSanitizer (zero reports allowed).
cmake --preset asan >/dev/null
cmake --build --preset asan
ctest --preset asan

# Fuzzing: libFuzzer targets (clang), a short fixed-seed run of each (docs/reliability.md).
bash scripts/fuzz.sh
