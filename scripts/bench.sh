#!/usr/bin/env bash
# Benchmarks: builds Release and runs the kernel benchmarks, amalgam vs Embree side by side.
#
#   scripts/bench.sh            full run (about 3 minutes on 2 cores) into out/bench/: results/
#                               (Google Benchmark JSON, the field's results.json and images),
#                               benchmarks.md and performance.md (copies of the docs pages
#                               with their generated tables rewritten); touches no docs
#   scripts/bench.sh --update-docs   the same into bench/results/, the tables in
#                               docs/benchmarks.md and the speed summary of docs/performance.md
#                               (between its bench markers), every ratio from this one run
#   scripts/bench.sh --quick    smoke run (smallest scenes, minimal time; seconds) of both
#                               benchmarks and the report, in a temporary directory; touches
#                               neither bench/results nor docs
#
# Environment: BUILD_DIR (default build, the release preset's directory),
# AMALGAM_BENCH_MAX_TRIANGLES (default 1e7; 1e8 needs ~30 GB and is skipped by default).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
mode=${1:-}
case "$mode" in
  "" | --quick | --update-docs) ;;
  *) echo "usage: scripts/bench.sh [--quick | --update-docs]" >&2; exit 2 ;;
esac
QUICK=0
[[ "$mode" == --quick ]] && QUICK=1
if [[ "$mode" == --update-docs ]]; then
  results=bench/results doc=docs/benchmarks.md summary=docs/performance.md
else
  results=out/bench/results doc=out/bench/benchmarks.md summary=out/bench/performance.md
fi

if [[ "$BUILD_DIR" == build ]]; then
  cmake --preset release >/dev/null
else
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
cmake --build "$BUILD_DIR" --target amalgam_embree_bench amalgam_bench amalgam_field_bench

if [[ $QUICK == 1 ]]; then
  exec bash bench/smoke.sh "$BUILD_DIR"
fi

mkdir -p "$results"
if [[ "$mode" != --update-docs ]]; then  # the generated parts are rewritten in copies
  cp docs/benchmarks.md "$doc"
  cp docs/performance.md "$summary"
fi
"$BUILD_DIR/bench/amalgam_embree_bench" --benchmark_out="$results/embree.json" \
  --benchmark_out_format=json 2> >(tee "$results/embree.log" >&2)
"$BUILD_DIR/bench/amalgam_bench" --benchmark_out="$results/traverse.json" \
  --benchmark_out_format=json

"$BUILD_DIR/bench/amalgam_field_bench" --out "$results/field"
python3 scripts/bench_report.py "$results/embree.json" "$results/embree.log" \
  "$results/field/results.json" "$doc" "$summary"
