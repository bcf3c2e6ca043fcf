#!/usr/bin/env python3
"""The meadow with k times more tufts in the same disc: tests per camera ray and time per
sample of each renderer, to see whether the cost of a ray stays flat as the scene grows (the
paper's O(log b) promise for amalgams, against O(log p) for full detail).

  python3 scripts/meadow_sweep.py                 # factors 1 and 10, 128x96, 1 spp
  python3 scripts/meadow_sweep.py --factors 1,10,80 --width 256 --height 192

Writes the scene variants, the stats JSON of every render and results.md (a table with
"tests per camera ray" and each factor's growth over factor 1) into --out (default
out/meadow-sweep). Every render: stratified sampling, 2 threads, seed 1; "render s" is the
renderer's own render phase, "total s" the wall-clock time of the whole process (load, build,
bake, render). Factor 80 (20 million instances, the scene loader's limit) needs about 12 GB
and several minutes.
"""

import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RENDERERS = ["traditional", "scale-sensitive", "volumetric"]


def variant(out, k):
    """scenes/meadow.json with k times its tufts (same disc), its mesh path made absolute."""
    with open(os.path.join(ROOT, "scenes", "meadow.json")) as f:
        scene = json.load(f)
    for m in scene["meshes"]:
        m["file"] = os.path.join(ROOT, "scenes", m["file"])
    first = scene["instances"][0]
    total = first["scatter"]["count"] * k
    # A scatter holds at most 2e7 instances: more are split into scatters of other seeds.
    parts = -(-total // 20_000_000)
    scene["instances"] = []
    for i in range(parts):
        part = json.loads(json.dumps(first))
        part["scatter"]["count"] = total // parts + (1 if i < total % parts else 0)
        part["scatter"]["seed"] = first["scatter"]["seed"] + i
        scene["instances"].append(part)
    path = os.path.join(out, f"meadow-x{k}.json")
    with open(path, "w") as f:
        json.dump(scene, f, indent=1)
    return path, total


def render(binary, scene, renderer, args, stats):
    cmd = [binary, "render", scene, "--renderer", renderer, "--width", str(args.width),
           "--height", str(args.height), "--spp", str(args.spp), "--sampler", "stratified",
           "--threads", "2", "--seed", "1", "--quiet", "--out", stats[:-5] + ".pfm",
           "--stats", stats]
    start = time.monotonic()
    done = subprocess.run(cmd, check=False)
    if done.returncode != 0:
        sys.exit(f"meadow_sweep.py: {' '.join(cmd)} failed (exit {done.returncode})")
    wall = time.monotonic() - start
    with open(stats) as f:
        j = json.load(f)
    return {"tests": j["per_primary_ray"]["mean"], "render_s": j["time_s"]["render"],
            "total_s": wall, "samples": args.width * args.height * args.spp}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--factors", default="1,10", help="tuft multipliers, comma separated")
    p.add_argument("--width", type=int, default=128)
    p.add_argument("--height", type=int, default=96)
    p.add_argument("--spp", type=int, default=1)
    p.add_argument("--out", default=os.path.join(ROOT, "out", "meadow-sweep"))
    p.add_argument("--binary", default=os.path.join(ROOT, "build", "amalgam"))
    args = p.parse_args()
    factors = [int(x) for x in args.factors.split(",")]
    if not factors or factors[0] != 1 or any(k < 1 for k in factors):
        sys.exit("meadow_sweep.py: --factors must start with 1 (the growth is measured from it)")
    os.makedirs(args.out, exist_ok=True)
    rows = {}
    for k in factors:
        scene, count = variant(args.out, k)
        for r in RENDERERS:
            res = render(args.binary, scene, r, args, os.path.join(args.out, f"x{k}-{r}.json"))
            res["count"] = count
            rows[(k, r)] = res
            print(f"x{k} {r}: {res['tests']:.0f} tests per camera ray, "
                  f"{res['render_s']:.3f} s render, {res['total_s']:.1f} s total", flush=True)
    lines = [
        f"Meadow sweep: {args.width}x{args.height}, {args.spp} spp, stratified, 2 threads "
        f"(`python3 scripts/meadow_sweep.py --factors {args.factors} --width {args.width} "
        f"--height {args.height} --spp {args.spp}`).",
        "",
        "| tufts | renderer | tests per camera ray | growth over x1 | render s | ns per sample "
        "(render) | total s |",
        "|---|---|---|---|---|---|---|",
    ]
    for k in factors:
        for r in RENDERERS:
            x = rows[(k, r)]
            growth = x["tests"] / rows[(1, r)]["tests"]
            lines.append(f"| {x['count']:,} | {r} | {x['tests']:.0f} | {growth:.2f}x | "
                         f"{x['render_s']:.3f} | {1e9 * x['render_s'] / x['samples']:.0f} | "
                         f"{x['total_s']:.1f} |")
    with open(os.path.join(args.out, "results.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
