#!/usr/bin/env bash
# Smoke run of every benchmark and of the report generator (seconds; no timing is judged):
#   bench/smoke.sh BUILD_DIR
# Runs amalgam_embree_bench on the smallest scene, amalgam_bench, amalgam_field_bench --quick,
# then scripts/bench_report.py on copies of README.md and docs/benchmarks.md, all in a
# temporary directory. Registered as the ctest `bench_smoke`; `scripts/bench.sh --quick` runs it.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "$1" && pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$build/bench/amalgam_embree_bench" --benchmark_filter='Build/tiny|Rays/tiny.*threads:1' \
  --benchmark_min_time=0.01 --benchmark_out="$out/embree.json" --benchmark_out_format=json \
  2>"$out/embree.log" >/dev/null
# Judge the agreement with Embree on the smoke scene, not only its presence: each ray set
# (primary, shadow, random) must give the same hit/miss on every ray (100 %) and the same
# closest t (within 1e-4 relative) on at least 99.99 % of them.
awk '
  /^agreement tiny_wuson/ {
    for (i = 1; i <= NF; ++i) {
      if ($i == "hit/miss") hit = $(i + 1)
      if ($i == "rel") t = $(i + 1)
    }
    sub(/%$/, "", hit); sub(/%$/, "", t)
    seen[$3] = 1
    if (hit + 0 < 100) { print "bench smoke: " $3 " rays: same hit/miss only " hit "% (Embree)"; bad = 1 }
    if (t + 0 < 99.99) { print "bench smoke: " $3 " rays: same t only " t "% (Embree)"; bad = 1 }
  }
  END {
    if (!("primary" in seen) || !("shadow" in seen) || !("random" in seen)) {
      print "bench smoke: agreement lines missing for primary, shadow or random rays"; bad = 1
    }
    exit bad
  }' "$out/embree.log" >&2
"$build/bench/amalgam_bench" --benchmark_min_time=0.01 >/dev/null
"$build/bench/amalgam_field_bench" --quick --out "$out/field" 2>/dev/null
cp "$root/README.md" "$root/docs/benchmarks.md" "$out/"
python3 "$root/scripts/bench_report.py" "$out/embree.json" "$out/embree.log" \
  "$out/field/results.json" "$out/benchmarks.md" "$out/README.md" >/dev/null
grep -q '| target | measured |' "$out/README.md"
echo "bench smoke: ok"
