#!/usr/bin/env bash
# Benchmarks: builds Release and runs the kernel benchmarks, amalgam vs Embree side by side.
#
#   scripts/bench.sh            full run (about 3 minutes on 2 cores): bench/results/ (Google
#                               Benchmark JSON, the field's results.json and images), the tables
#                               in docs/benchmarks.md and the README's speed section (between
#                               its bench markers), every ratio from this one run
#   scripts/bench.sh --quick    smoke run (smallest scenes, minimal time; seconds) of both
#                               benchmarks and the report, in a temporary directory; touches
#                               neither bench/results nor docs nor README.md
#
# Environment: BUILD_DIR (default build, the release preset's directory),
# AMALGAM_BENCH_MAX_TRIANGLES (default 1e7; 1e8 needs ~30 GB and is skipped by default).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
QUICK=0
[[ "${1:-}" == "--quick" ]] && QUICK=1

if [[ "$BUILD_DIR" == build ]]; then
  cmake --preset release >/dev/null
else
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
cmake --build "$BUILD_DIR" --target amalgam_embree_bench amalgam_bench amalgam_field_bench

if [[ $QUICK == 1 ]]; then
  exec bash bench/smoke.sh "$BUILD_DIR"
fi

mkdir -p bench/results
"$BUILD_DIR/bench/amalgam_embree_bench" --benchmark_out=bench/results/embree.json \
  --benchmark_out_format=json 2> >(tee bench/results/embree.log >&2)
"$BUILD_DIR/bench/amalgam_bench" --benchmark_out=bench/results/traverse.json \
  --benchmark_out_format=json

"$BUILD_DIR/bench/amalgam_field_bench" --out bench/results/field
python3 scripts/bench_report.py bench/results/embree.json bench/results/embree.log \
  bench/results/field/results.json docs/benchmarks.md README.md
