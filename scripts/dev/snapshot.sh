#!/usr/bin/env bash
# Renders a fixed set of scenes (every builtin, a mesh, scene files, the quick experiments) into
# DIR, with timings, the peak memory and the command line removed from the stats files, so that
# two builds can be compared with `cmp` / `diff -r`: a refactoring must leave every byte of
# these outputs unchanged.
#   scripts/dev/snapshot.sh BINARY DIR
set -euo pipefail
bin=$(realpath "$1"); out=$2
root=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$out"; cd "$out"
wuson=/usr/share/assimp/models/PLY/Wuson.ply
engine=/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb
r() {  # name, then render arguments
  local name=$1; shift
  "$bin" render "$@" --quiet --threads 2 --out "$name.pfm" --cost-image "$name-cost.pfm" \
    --stats "$name.json"
  python3 - "$name.json" <<'PY'
import json, sys
p = sys.argv[1]; j = json.load(open(p))
for k in ("time_s", "peak_memory_bytes", "command_line"): j.pop(k, None)
for k in ("bake_s", "world_bake_s"): j.get("volumes", {}).pop(k, None)
open(p, "w").write(json.dumps(j, indent=1, sort_keys=True) + "\n")
PY
}
r line builtin:line --width 64 --height 64 --spp 2
r line-det builtin:line --set alpha=0.5 --opacity deterministic --width 64 --height 64 --spp 2
r prisms builtin:prisms --width 96 --height 96 --spp 2
r prisms-level builtin:prisms --set view=corner --level 3 --width 96 --height 96 --spp 2
r prisms-det builtin:prisms --set view=corner --level 3 --opacity deterministic --width 96 --height 96 --spp 2
r prisms-trad builtin:prisms --renderer traditional --order unsorted --width 96 --height 96 --spp 2
r poisson builtin:poisson --width 64 --height 64 --spp 2
r demo builtin:demo --width 128 --height 128 --spp 2
r demo-fp builtin:demo --footprint 4 --width 128 --height 128 --spp 2
r wuson "$wuson" --width 128 --height 128 --spp 2
r wuson-fp "$wuson" --footprint 2 --width 128 --height 128 --spp 2
r wuson-det "$wuson" --footprint 2 --opacity deterministic --width 96 --height 96 --spp 2
r engine "$engine" --width 128 --height 128 --spp 2
r field "$root/scenes/field.json" --width 160 --height 120 --spp 2
r field-fp "$root/scenes/field.json" --footprint 2 --width 160 --height 120 --spp 2
r field-trad "$root/scenes/field.json" --renderer traditional --width 160 --height 120 --spp 1
r wuson-grid "$root/scenes/wuson-grid.json" --footprint 1 --width 128 --height 96 --spp 2
r spheres "$root/scenes/spheres.json" --footprint 1 --width 96 --height 96 --spp 2
# The volumetric renderer: object cells (open and closed objects), world cells, a sky.
vol() { local name=$1; shift; r "$name" "$@" --renderer volumetric --sampler stratified; }
vol vol-tree "$root/scenes/volumetric/tree.json" --eye 0,89,125 --look-at 0,3,0 --width 64 --height 48 --spp 2
vol vol-tree-near "$root/scenes/volumetric/tree.json" --width 64 --height 48 --spp 2
vol vol-sphere "$root/scenes/volumetric/sphere.json" --eye 0,7,10 --look-at 0,0.5,0 --width 64 --height 48 --spp 2
vol vol-wuson "$root/scenes/volumetric/wuson.json" --eye 0,9,13 --look-at 0,0.4,0 --width 64 --height 48 --spp 2
vol vol-crowd "$root/tests/data/crowd.json" --width 64 --height 48 --spp 2
vol vol-forest "$root/scenes/forest.json" --width 96 --height 64 --spp 1
cat > forest-sky.json <<JSON
{"camera": {"position": [0, 70, 150], "look_at": [0, 0, 40], "vfov": 40},
 "lights": [{"type": "directional", "direction": [0.45, -1, -0.6], "intensity": [2.4, 2.3, 2.1]},
            {"type": "sky", "radiance": [0.35, 0.45, 0.65], "samples": 2}],
 "materials": {"soil": {"colour": [0.3, 0.22, 0.15]}},
 "meshes": [{"name": "tree", "file": "$root/scenes/volumetric/tree.obj", "place": false}],
 "instances": [{"mesh": "tree", "scatter": {"count": 500, "radius": 60, "seed": 11}}],
 "boxes": [{"min": [-70, -0.05, -70], "max": [70, 0, 70], "material": "soil"}]}
JSON
vol vol-forest-sky forest-sky.json --width 96 --height 64 --spp 1
r trad-forest-sky forest-sky.json --renderer traditional --width 96 --height 64 --spp 1
"$bin" trace builtin:line --set n=3 --set depth=6 --renderer traditional | grep -v -E "\"(load|build|bake|render)\":" > trace-line.txt
"$bin" experiment all --quick --out exp >/dev/null
rm -f exp/report.md.tmp*
# report.md holds wall-clock times: drop the lines that name seconds.
grep -v -i -E "seconds| s\)|time" exp/report.md > exp/report.filtered || true
rm exp/report.md
echo "snapshot: $(ls | wc -l) files in $out"
