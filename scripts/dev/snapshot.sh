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
"$bin" trace builtin:line --set n=3 --set depth=6 --renderer traditional | grep -v -E "\"(load|build|bake|render)\":" > trace-line.txt
"$bin" experiment all --quick --out exp >/dev/null
rm -f exp/report.md.tmp*
# report.md holds wall-clock times: drop the lines that name seconds.
grep -v -i -E "seconds| s\)|time" exp/report.md > exp/report.filtered || true
rm exp/report.md
echo "snapshot: $(ls | wc -l) files in $out"
