#!/usr/bin/env bash
# Fuzzing: builds the libFuzzer targets (in the sanitizer tree build-asan/: CMake preset
# `asan`, clang-14, ASan + UBSan; build preset `fuzz` builds only them) and runs each one for
# a fixed time with a fixed seed, starting from the committed seed corpus in
# fuzz/corpus/<target>/. Fails on any crash, sanitizer report, leak, timeout or
# out-of-memory; the offending input is kept in build-asan/artifacts/.
#
#   scripts/fuzz.sh             CI mode: a fixed number of inputs per target (deterministic:
#                               the same inputs on any machine; docs/testing.md has the time)
#   scripts/fuzz.sh --long      the slow target (mesh: every input starts the import helper)
#                               with more inputs: the same seed, so a superset of the above
#                               (scripts/test.sh --long)
#   scripts/fuzz.sh SECONDS     SECONDS per target instead; the targets run side by side
#
# New inputs found during the run go to a scratch directory and are thrown away, so the
# committed corpus only changes by hand. Long runs: see docs/reliability.md.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-}
targets=(scene_json params mesh checkpoint image)
declare -A runs_ci=([scene_json]=5000 [params]=6000 [mesh]=400 [checkpoint]=5000 [image]=5000)
if [ "$seconds" = --long ]; then
  seconds=""
  targets=(mesh)
  runs_ci=([mesh]=1500)
fi

bash scripts/deps.sh --test  # clang-14 and its libFuzzer runtime
cmake --preset asan >/dev/null
cmake --build --preset fuzz  # the fuzz targets of the sanitizer tree (nothing if built)

export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
mkdir -p build-asan/artifacts

pids=()
for t in "${targets[@]}"; do
  mkdir -p "$scratch/$t"
  dict=()
  [ -f "fuzz/$t.dict" ] && dict=("-dict=fuzz/$t.dict")
  if [ -n "$seconds" ]; then limit=("-max_total_time=$seconds"); else limit=("-runs=${runs_ci[$t]}"); fi
  build-asan/${t}_fuzz -seed=1 "${limit[@]}" -timeout=20 -rss_limit_mb=2560 \
    -print_final_stats=1 "${dict[@]}" -artifact_prefix="build-asan/artifacts/$t-" \
    "$scratch/$t" "fuzz/corpus/$t" >"$scratch/$t.log" 2>&1 &
  pids+=($!)
done

status=0
for i in "${!targets[@]}"; do
  t=${targets[$i]}
  if wait "${pids[$i]}"; then
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$scratch/$t.log")
    speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$scratch/$t.log")
    cov=$(grep -o 'cov: [0-9]*' "$scratch/$t.log" | tail -n 1)
    echo "fuzz: $t: ok, ${runs:-?} inputs (${speed:-?}/s), $cov"
  else
    status=1
    cp "$scratch/$t.log" "build-asan/artifacts/$t.log"
    grep -v '^#' "$scratch/$t.log" | tail -n 60 >&2
    echo "fuzz: $t FAILED: the input and the log are in build-asan/artifacts/ (add it to" \
      "tests/fuzz_regressions_test.cpp once fixed)" >&2
  fi
done
exit $status
