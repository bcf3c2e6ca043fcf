#!/usr/bin/env python3
"""Measures world cells (docs/volumetric.md, "World cells"): the volumetric renderer against full
detail on crowds of instances smaller than a pixel, and how the cost of a camera ray grows with
the crowd.

Scenes: tests/data/crowd.json (40,000 tufts of 15 cm on a disc of 5 m, seen from 43 m) and the
same crowd k times larger (k^2 times the tufts on a disc k times wider, the camera k times
farther, at k times the resolution: the same pixels per tuft), each also with ten times the
tufts in the same disc. Per scene: a converged full-detail reference (traditional, stratified,
--ref-spp), then the traditional renderer at 16 spp and the volumetric renderer at 1, 2, 4 and 16
spp, seeds 1-3, stratified, 2 threads. Reported: RMSE against the reference (mean over seeds),
the worst 16 x 16 tile of the 3-seed mean and the frame (relative luminance), tests per camera
ray (every test a camera sample causes, shadows included: the stats' per_primary_ray), render
seconds and wall-clock seconds of the whole process (load, build, bakes, render). Then the
fewest volumetric spp whose RMSE is at most the traditional renderer's at 16 spp, and the
ratio of times at that equal error.

Usage: /usr/bin/python3 scripts/world_cells_eval.py [--doc docs/volumetric] [--sizes 1,4]
Needs Debian's python3-numpy.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import pfm  # noqa: E402
from volumetric_eval import machine  # noqa: E402

LUM = np.array([0.2126, 0.7152, 0.0722])
SEEDS = (1, 2, 3)
TILE = 16


def crowd(tmp, k, density):
    """tests/data/crowd.json k times larger, with `density` times the tufts per area."""
    with open(os.path.join(ROOT, "tests", "data", "crowd.json")) as f:
        s = json.load(f)
    for m in s["meshes"]:
        m["file"] = os.path.join(ROOT, "scenes", os.path.basename(m["file"]))
    sc = s["instances"][0]["scatter"]
    sc["count"] = sc["count"] * k * k * density
    sc["radius"] = sc["radius"] * k
    s["camera"]["position"] = [c * k for c in s["camera"]["position"]]
    for b in s["boxes"]:
        b["min"] = [b["min"][0] * k, b["min"][1], b["min"][2] * k]
        b["max"] = [b["max"][0] * k, b["max"][1], b["max"][2] * k]
    path = os.path.join(tmp, f"crowd-k{k}-d{density}.json")
    with open(path, "w") as f:
        json.dump(s, f)
    return path, sc["count"]


def render(binary, scene, renderer, w, h, spp, seed, out):
    stats = out + ".json"
    cmd = [binary, "render", scene, "--renderer", renderer, "--width", str(w), "--height", str(h),
           "--spp", str(spp), "--sampler", "stratified", "--threads", "2", "--seed", str(seed),
           "--quiet", "--out", out, "--stats", stats]
    start = time.monotonic()
    subprocess.run(cmd, check=True)
    wall = time.monotonic() - start
    with open(stats) as f:
        j = json.load(f)
    return {"image": pfm.read_pfm(out)[..., :3] @ LUM, "wall": wall,
            "render": j["time_s"]["render"], "tests": j["per_primary_ray"]["mean"]}


def tiles(img, ref):
    h, w = ref.shape
    errs = [img[y:y + TILE, x:x + TILE].mean() / ref[y:y + TILE, x:x + TILE].mean() - 1
            for y in range(0, h, TILE) for x in range(0, w, TILE)]
    return max(abs(e) for e in errs), img.mean() / ref.mean() - 1


def measure(binary, tmp, k, density, ref_spp):
    scene, count = crowd(tmp, k, density)
    w, h = 64 * k, 48 * k
    ref = render(binary, scene, "traditional", w, h, ref_spp, 100, os.path.join(tmp, "ref.pfm"))
    rows = []
    for renderer, spps in (("traditional", (16,)), ("volumetric", (1, 2, 4, 16))):
        for spp in spps:
            runs = [render(binary, scene, renderer, w, h, spp, s, os.path.join(tmp, "r.pfm"))
                    for s in SEEDS]
            mean = sum(r["image"] for r in runs) / len(runs)
            tile, frame = tiles(mean, ref["image"])
            rows.append({
                "renderer": renderer, "spp": spp,
                "rmse": float(np.mean([np.sqrt(((r["image"] - ref["image"]) ** 2).mean())
                                       for r in runs])),
                "tile": tile, "frame": frame,
                "tests": float(np.mean([r["tests"] for r in runs])),
                "render": float(np.mean([r["render"] for r in runs])),
                "wall": float(np.mean([r["wall"] for r in runs]))})
            print(f"k={k} x{density} {renderer} {spp} spp: {rows[-1]}", flush=True)
    return {"k": k, "density": density, "tufts": count, "width": w, "height": h, "rows": rows}


def table(results):
    out = ["| scene | tufts | renderer | spp | RMSE | worst tile | frame | tests per camera ray "
           "| render s | wall s |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        name = f"crowd x{r['k']}" + (f", {r['density']}x dense" if r["density"] > 1 else "") + \
            f" ({r['width']}x{r['height']})"
        for x in r["rows"]:
            out.append(f"| {name} | {r['tufts']:,} | {x['renderer']} | {x['spp']} | "
                       f"{x['rmse']:.4f} | {100 * x['tile']:.1f} % | {100 * x['frame']:+.2f} % | "
                       f"{x['tests']:.1f} | {x['render']:.3f} | {x['wall']:.2f} |")
    return out


def verdicts(results):
    out = ["| scene | traditional 16 spp RMSE | volumetric spp at that RMSE | render time ratio "
           "| wall time ratio | tests ratio |", "|---|---|---|---|---|---|"]
    for r in results:
        trad = r["rows"][0]
        vol = [x for x in r["rows"][1:] if x["rmse"] <= trad["rmse"]]
        name = f"crowd x{r['k']}" + (f", {r['density']}x dense" if r["density"] > 1 else "")
        if not vol:
            out.append(f"| {name} | {trad['rmse']:.4f} | none up to 16 | - | - | - |")
            continue
        v = vol[0]
        out.append(f"| {name} | {trad['rmse']:.4f} | {v['spp']} | "
                   f"{trad['render'] / v['render']:.1f}x less | {trad['wall'] / v['wall']:.2f}x | "
                   f"{v['tests'] / trad['tests']:.3f} |")
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--amalgam", default=os.path.join(ROOT, "build", "amalgam"))
    p.add_argument("--sizes", default="1,4", help="crowd scales k, comma separated")
    p.add_argument("--ref-spp", type=int, default=256)
    p.add_argument("--doc", help="directory to write world-cells.md and world-cells.json into")
    args = p.parse_args()
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in (int(x) for x in args.sizes.split(",")):
            for density in (1, 10):
                results.append(measure(args.amalgam, tmp, k, density, args.ref_spp))
    # Flat cost: tests per camera ray of each renderer, ten times denser over plain.
    flat = ["| scene | renderer | tests per camera ray | 10x dense | growth |", "|---|---|---|---|---|"]
    for a, b in zip(results[0::2], results[1::2]):
        for i in (0, 2):
            x, y = a["rows"][i], b["rows"][i]
            flat.append(f"| crowd x{a['k']} | {x['renderer']} {x['spp']} spp | {x['tests']:.1f} | "
                        f"{y['tests']:.1f} | {y['tests'] / x['tests']:.2f}x |")
    cmd = f"/usr/bin/python3 scripts/world_cells_eval.py --sizes {args.sizes} --doc docs/volumetric"
    lines = [
        "# World cells: measured",
        "",
        f"Written by `{cmd}` ({machine()}); reference: full detail at {args.ref_spp} spp. "
        "Stratified sampling, 2 threads, seeds 1-3 (RMSE: their mean; tiles and frame: of their "
        "mean image). Tests per camera ray include the shadow tests a camera sample causes.",
        "",
        "## Every run",
        "",
        *table(results),
        "",
        "## At equal error",
        "",
        "The fewest volumetric samples per pixel whose RMSE is at most the traditional "
        "renderer's at 16 spp, and the ratios at that error (render time and wall-clock time: "
        "traditional over volumetric; tests: volumetric over traditional).",
        "",
        *verdicts(results),
        "",
        "## Cost as the crowd grows",
        "",
        *flat,
        "",
    ]
    text = "\n".join(lines)
    print(text)
    if args.doc:
        os.makedirs(args.doc, exist_ok=True)
        with open(os.path.join(args.doc, "world-cells.md"), "w") as f:
            f.write(text)
        with open(os.path.join(args.doc, "world-cells.json"), "w") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
