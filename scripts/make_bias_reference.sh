#!/usr/bin/env bash
# Regenerates tests/data/bias-meadow-ref.pfm, the converged full-detail reference of the bias
# test (tests/render/bias_reference_test.cpp): the traditional renderer (every amalgam a plain
# bounding volume), stratified pixel sampling, 1024 samples per pixel, 128 x 96. Deterministic
# (seed 1, any thread count): rerunning it rewrites the same bytes. About 7 CPU-minutes.
#
#   scripts/make_bias_reference.sh [path/to/amalgam]      (default: build/amalgam)
set -euo pipefail
cd "$(dirname "$0")/.."
AMALGAM=${1:-build/amalgam}
"$AMALGAM" render tests/data/bias-meadow.json --renderer traditional --sampler stratified \
  --spp 1024 --seed 1 --width 128 --height 96 --quiet --out tests/data/bias-meadow-ref.pfm
# The world cells' crowd (tests/render/world_cells_test.cpp): 64 x 48, 1024 spp, a few seconds.
"$AMALGAM" render tests/data/crowd.json --renderer traditional --sampler stratified \
  --spp 1024 --seed 1 --width 64 --height 48 --quiet --out tests/data/crowd-ref.pfm
