#!/usr/bin/env bash
# Quick start, command 1: install what is missing, build Release, render the demo.
#
# The demo renders one herd of 17,000 Wusons at two scene sizes (6.3e7 and 1.6e10 triangles:
# the same meshes subdivided 0 and 4 times), each traditionally (every bounding volume
# traversed) and scale-sensitively (amalgams about a pixel wide rendered instead), and composes
# out/demo.png: the images, their exact cost per pixel on one shared log scale, and the level
# rendered at each pixel. Traditional cost grows with the scene; scale-sensitive cost does not.
#
# --update-docs also copies the strip to docs/img/demo.png and rewrites the README caption's
# figures from these renders (scripts/figures.py; the docs_figures test re-measures them).
set -euo pipefail
cd "$(dirname "$0")/.."
update_docs=0
case "${1:-}" in
  "") ;;
  --update-docs) update_docs=1 ;;
  *) echo "usage: scripts/demo.sh [--update-docs]" >&2; exit 2 ;;
esac
bash scripts/deps.sh --demo  # the CLI's packages only; scripts/test.sh installs the rest
# No tests or benchmarks here (their libraries are not installed yet); scripts/test.sh turns
# them on in the same tree, whose objects it then reuses.
cmake --preset release -DAMALGAM_BUILD_TESTS=OFF -DAMALGAM_BUILD_BENCH=OFF >/dev/null
cmake --build --preset release --target amalgam  # the CLI and its import helper only
out=out/demo
mkdir -p "$out"
size=(--width 480 --height 360 --spp 4)
for scene in coarse fine; do
  for renderer in traditional scale-sensitive; do
    name="$renderer-$scene"
    ./build/amalgam render "scenes/demo-field-$scene.json" --renderer "$renderer" "${size[@]}" \
      --out "$out/$name.png" --cost-image "$out/$name-cost.pfm" \
      --level-image "$out/$name-level.pfm" --stats "$out/$name.json" --quiet
    printf '%-28s %s tests per primary ray (shadow rays included)\n' "$name" \
      "$(/usr/bin/python3 -c 'import json,sys; print(round(json.load(open(sys.argv[1]))["per_primary_ray"]["mean"], 1))' "$out/$name.json")"
  done
done
cat >"$out/strip.json" <<'EOF'
{"title": "17,000 Wusons at two scene sizes: 6.3e7 triangles (left pair), 1.6e10 triangles (right pair)",
 "columns": [
  {"name": "traditional-coarse", "title": "6.3e7 triangles, traditional", "renderer": "traditional"},
  {"name": "scale-sensitive-coarse", "title": "6.3e7, scale-sensitive", "renderer": "scale-sensitive"},
  {"name": "traditional-fine", "title": "1.6e10 triangles, traditional", "renderer": "traditional"},
  {"name": "scale-sensitive-fine", "title": "1.6e10, scale-sensitive", "renderer": "scale-sensitive"}]}
EOF
/usr/bin/python3 scripts/demo_strip.py "$out" out/demo.png
if ((update_docs)); then
  cp out/demo.png docs/img/demo.png
  /usr/bin/python3 scripts/figures.py update --only demo --demo-dir "$out"
fi
echo "demo strip: $(pwd)/out/demo.png (renders, cost and level images, stats: $out/)"
