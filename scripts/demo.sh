#!/usr/bin/env bash
# Quick start, command 1: install what is missing, build Release, render the demo scene.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
cmake --preset release >/dev/null
cmake --build --preset release
mkdir -p out
./build/amalgam render builtin:demo --width 768 --height 768 --spp 8 \
  --out out/demo.png --cost-image out/demo-cost.png --stats out/demo-stats.json
echo "demo image: $(pwd)/out/demo.png (cost image: out/demo-cost.png, stats: out/demo-stats.json)"
