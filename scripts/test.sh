#!/usr/bin/env bash
# Quick start, command 2: install what is missing, build, run every test.
#
#   scripts/test.sh          the release suite; the same suite under ASan + UBSan (clang), but
#                            for the few tests that take longest there; a short fixed-seed run
#                            of every fuzz target (built in the same sanitizer tree)
#   scripts/test.sh --long   what the first leaves out: those long tests under ASan + UBSan,
#                            and a longer run of the slowest fuzz target (.ci/run runs both, so
#                            every test runs under the sanitizers in CI)
#
# Each stage prints its wall-clock time; with AMALGAM_TEST_TIMES=FILE it is also appended to
# FILE as "stage<TAB>seconds" (scripts/test_times.py turns that into docs/testing.md's table).
set -euo pipefail
cd "$(dirname "$0")/.."
long=0
case "${1:-}" in
  "") ;;
  --long) long=1 ;;
  *) echo "usage: scripts/test.sh [--long]" >&2; exit 2 ;;
esac

stage() {  # NAME COMMAND...: runs COMMAND, reports how long it took
  local name=$1 t0 t1
  shift
  t0=$(date +%s.%N)
  "$@"
  t1=$(date +%s.%N)
  local s
  s=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')
  echo "test.sh: $name: $s s" >&2
  if [ -n "${AMALGAM_TEST_TIMES:-}" ]; then printf '%s\t%s\n' "$name" "$s" >>"$AMALGAM_TEST_TIMES"; fi
}

stage "install packages" bash scripts/deps.sh --test

if ((long)); then
  # The sanitizer tree is built by the default run; built here too if this runs alone.
  stage "asan: configure" cmake --preset asan >/dev/null
  stage "asan: build" cmake --build --preset asan
  stage "asan: long tests" ctest --preset asan-long
  stage "fuzz: long run" bash scripts/fuzz.sh --long
  exit 0
fi

# Every part on, whatever an earlier configure of build/ left in its cache (scripts/demo.sh
# configures it without tests and benchmarks, before their packages are installed).
stage "release: configure" cmake --preset release -DAMALGAM_BUILD_TESTS=ON \
  -DAMALGAM_BUILD_BENCH=ON -DAMALGAM_PYTHON=ON -DAMALGAM_MPI=ON >/dev/null
stage "release: build" cmake --build --preset release
stage "release: tests" ctest --preset release

# The same suite under AddressSanitizer + UndefinedBehaviorSanitizer (zero reports allowed).
stage "asan: configure" cmake --preset asan >/dev/null
stage "asan: build" cmake --build --preset asan
stage "asan: tests" ctest --preset asan

# Fuzzing: the libFuzzer targets, a short fixed-seed run of each (docs/reliability.md).
stage "fuzz: run" bash scripts/fuzz.sh
