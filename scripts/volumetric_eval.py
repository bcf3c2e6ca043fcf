#!/usr/bin/env python3
"""Measures volumetric amalgams (`amalgam render --renderer volumetric`) against full detail on
views of single objects and on tests/data/bias-meadow.json (docs/volumetric.md).

For each view: a full-detail render at F x F sub-pixels per pixel (traditional renderer,
stratified) gives the converged reference (its pixel means), the ideal bound of
scripts/lod_bound.py (the reference blurred by a disc of the cone's width, sampled at n
stratified points per pixel) and the footprint-filtered reference (that blurred image's pixel
means: what a perfect prefiltering at this cone width converges to). Then the volumetric and the
traditional renderers at --spp samples (stratified), three seeds each, are compared with both
references:

- rmse: per seed, against the reference; bias / sd: the root mean square of the mean over the
  seeds minus the reference, and of one run's standard deviation (the split of the RMSE);
- tiles: each 32 x 32 tile's mean luminance over the seeds against the reference's (worst |.|,
  relative), and the frame's; `object`: the error of the object's contribution (the sum over
  pixels of the difference, over the sum of |reference - the view without the object|);
- hf: high-frequency energy (luminance minus its 3 x 3 box blur, mean square) of the seed mean,
  less the noise's share, over the reference's;
- achieved / ideal: RMSE at 1 spp over the ideal renderer's at the same footprint;
- tests per camera ray over the object's pixels (where the object changes the reference), and
  time per sample.

Usage: scripts/volumetric_eval.py [--amalgam build/amalgam] [--views NAME,...] [--json out.json]
Needs Debian's python3-numpy (run with /usr/bin/python3).
"""

import argparse
import hashlib
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
import lod_bound  # noqa: E402
import pfm  # noqa: E402

LUM = np.array([0.2126, 0.7152, 0.0722])

def looking_down(target, distance, elevation_deg=35.0):
    """Camera options for a view of `target` from `distance` at `elevation_deg` above the
    horizon: with the scenes' 30-degree field of view, the frame holds ground and object only
    (no horizon), so tile and frame means weigh the object and its shadow."""
    e = elevation_deg * 3.141592653589793 / 180.0
    import math
    eye = (target[0], target[1] + distance * math.sin(e), target[2] + distance * math.cos(e))
    return ["--eye", ",".join(f"{x:g}" for x in eye), "--look-at", ",".join(f"{x:g}" for x in target)]


# name: (scene, extra render options, width, height). Distances chosen so that the object
# covers from about 1 to 50 pixels (128 x 96, 30-degree field of view: a pixel is 0.0055 rad).
VIEWS = {
    "tuft-10": ("scenes/volumetric/tuft.json", looking_down((0, 0.2, 0), 10), 128, 96),
    "tuft-25": ("scenes/volumetric/tuft.json", looking_down((0, 0.2, 0), 25), 128, 96),
    "tuft-60": ("scenes/volumetric/tuft.json", looking_down((0, 0.2, 0), 60), 128, 96),
    "wuson-15": ("scenes/volumetric/wuson.json", looking_down((0, 0.4, 0), 15), 128, 96),
    "wuson-40": ("scenes/volumetric/wuson.json", looking_down((0, 0.4, 0), 40), 128, 96),
    "tree-150": ("scenes/volumetric/tree.json", looking_down((0, 3, 0), 150), 128, 96),
    "tree-400": ("scenes/volumetric/tree.json", looking_down((0, 3, 0), 400), 128, 96),
    "sphere-12": ("scenes/volumetric/sphere.json", looking_down((0, 0.5, 0), 12), 128, 96),
    "sphere-40": ("scenes/volumetric/sphere.json", looking_down((0, 0.5, 0), 40), 128, 96),
    "bias-meadow": ("tests/data/bias-meadow.json", [], 128, 96),
}


def lum(img):
    return img @ LUM


def run(cmd):
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)


_HASHES = {}


def binary_hash(path):
    """The executable's content hash: a rebuilt renderer never reads another's cached images."""
    if path not in _HASHES:
        with open(path, "rb") as f:
            _HASHES[path] = hashlib.sha1(f.read()).hexdigest()
    return _HASHES[path]


class Cache:
    """Renders keyed by their command line (references take the longest)."""

    def __init__(self, folder):
        self.folder = folder
        os.makedirs(folder, exist_ok=True)

    def render(self, amalgam, args, with_stats=False):
        key = hashlib.sha1(" ".join([binary_hash(amalgam)] + args).encode()).hexdigest()[:16]
        img = os.path.join(self.folder, key + ".pfm")
        stats = os.path.join(self.folder, key + ".json")
        cost = os.path.join(self.folder, key + "-cost.pfm")
        if not os.path.exists(img):
            cmd = [amalgam, "render"] + args + ["--quiet", "--out", img + ".tmp.pfm"]
            if with_stats:
                cmd += ["--stats", stats, "--cost-image", cost]
            t0 = time.time()
            run(cmd)
            os.replace(img + ".tmp.pfm", img)
            if with_stats:
                with open(stats) as f:
                    s = json.load(f)
                s["wall_s"] = time.time() - t0
                with open(stats, "w") as f:
                    json.dump(s, f)
        out = {"image": pfm.read_pfm(img).astype(np.float64)}
        if with_stats:
            with open(stats) as f:
                out["stats"] = json.load(f)
            out["cost"] = pfm.read_pfm(cost)[..., 0].astype(np.float64)
        return out


def without_objects(scene_path):
    """A copy of the scene file without its meshes and instances, with absolute paths."""
    with open(scene_path) as f:
        text = "\n".join(line for line in f if not line.lstrip().startswith("//"))
    s = json.loads(text)
    s.pop("meshes", None)
    s.pop("instances", None)
    fd, path = tempfile.mkstemp(suffix=".json", prefix="amalgam-empty-")
    with os.fdopen(fd, "w") as f:
        json.dump(s, f)
    return path


def hf_energy(l):
    pad = np.pad(l, 1, mode="edge")
    box = sum(pad[1 + dy:1 + dy + l.shape[0], 1 + dx:1 + dx + l.shape[1]]
              for dy in (-1, 0, 1) for dx in (-1, 0, 1)) / 9.0
    return float(np.mean((l - box) ** 2))


def tiles(l, t=32):
    H, W = l.shape
    return np.array([[l[y:y + t, x:x + t].mean() for x in range(0, W, t)] for y in range(0, H, t)])


def evaluate(a, name, cache):
    scene, view, w, h = VIEWS[name]
    scene = os.path.join(ROOT, scene)
    f = a.factor
    common = ["--sampler", "stratified", "--threads", str(a.threads)] + view
    hi = cache.render(a.amalgam, [scene, "--renderer", "traditional", "--width", str(w * f),
                                  "--height", str(h * f), "--spp", str(a.ref_spp), "--seed",
                                  "11"] + common)["image"]
    ref = hi.reshape(h, f, w, f, 3).mean(axis=(1, 3))
    empty_scene = without_objects(scene)
    try:
        empty = cache.render(a.amalgam, [empty_scene, "--renderer", "traditional", "--width",
                                         str(w), "--height", str(h), "--spp", "64"] + common)["image"]
    finally:
        os.unlink(empty_scene)
    contribution = np.abs(lum(ref) - lum(empty))
    obj = contribution > 1e-3
    near = obj.copy()  # the object's pixels and two around them: where it can change anything
    for _ in range(2):
        p = np.pad(near, 1)
        near = p[1:-1, 1:-1] | p[:-2, 1:-1] | p[2:, 1:-1] | p[1:-1, :-2] | p[1:-1, 2:]
    rng = np.random.default_rng(1)
    k = a.footprint
    blurred = lod_bound.disc_blur(hi, k * f)
    ref_cone = blurred.reshape(h, f, w, f, 3).mean(axis=(1, 3))
    ideal_1spp = lod_bound.rmse_at(blurred.reshape(h, f, w, f, 3), ref, 1, f, 8, rng)
    ideal_spp = lod_bound.rmse_at(blurred.reshape(h, f, w, f, 3), ref, a.spp, f, 8, rng)
    result = {"view": name, "width": w, "height": h, "object_pixels": int(obj.sum()),
              "ideal_rmse_1spp": ideal_1spp, "ideal_rmse": ideal_spp,
              "ref_cone_rmse": float(np.sqrt(np.mean((ref_cone - ref) ** 2))),
              "hf_ideal": hf_energy(lum(ref_cone)) / hf_energy(lum(ref)), "renderers": {}}
    images = {}
    renderers = {"volumetric": ["--renderer", "volumetric", "--footprint", str(k)] + a.extra,
                 "traditional": ["--renderer", "traditional"]}
    for rname, ropts in renderers.items():
        row = {}
        for spp in sorted({1, a.spp}):
            runs = [cache.render(a.amalgam, [scene, "--width", str(w), "--height", str(h), "--spp",
                                             str(spp), "--seed", str(seed)] + ropts + common,
                                 with_stats=True) for seed in (1, 2, 3)]
            imgs = np.stack([r["image"] for r in runs])
            mean = imgs.mean(axis=0)
            rmse = float(np.mean([np.sqrt(np.mean((i - ref) ** 2)) for i in imgs]))
            sd = float(np.sqrt(np.mean(imgs.var(axis=0, ddof=1))))
            bias = float(np.sqrt(max(np.mean((mean - ref) ** 2) - sd ** 2 / 3, 0.0)))
            bias_cone = float(np.sqrt(max(np.mean((mean - ref_cone) ** 2) - sd ** 2 / 3, 0.0)))
            tl, tr = tiles(lum(mean)), tiles(lum(ref))
            tile_rel = (tl - tr) / tr
            lm, lr = lum(mean), lum(ref)
            noise_hf = (8.0 / 9.0) * float(np.mean(lum(imgs).var(axis=0, ddof=1))) / 3
            hf = (hf_energy(lm) - noise_hf) / hf_energy(lr)
            cost = np.mean([r["cost"] for r in runs], axis=0)
            st = runs[0]["stats"]
            samples = w * h * spp
            row[spp] = {
                "rmse": rmse, "sd": sd, "bias": bias, "bias_vs_cone_ref": bias_cone,
                "tile_worst": float(tile_rel.flat[np.argmax(np.abs(tile_rel))]),
                "tiles": [round(float(x), 4) for x in tile_rel.flat],
                "frame": float(lm.mean() / lr.mean() - 1),
                "object": float((lm - lr)[near].sum() / contribution.sum()),
                "object_sums": [float((lum(i) - lr)[near].sum()) for i in imgs],
                "object_se": float(np.std([(lum(i) - lr)[near].sum() for i in imgs], ddof=1)
                                   / np.sqrt(len(imgs)) / contribution.sum()),
                "object_l1": float(np.abs(lm - lr)[near].sum() / contribution.sum()),
                "hf": hf,
                "tests_object": float(cost[obj].mean()) if obj.any() else None,
                "tests_frame": float(cost.mean()),
                "render_s": float(np.mean([r["stats"]["time_s"]["render"] for r in runs])),
                "ns_per_sample": 1e9 * float(np.mean([r["stats"]["time_s"]["render"] for r in runs])) / samples,
                "bake_s": st.get("volumes", {}).get("bake_s"),
            }
            if spp == 1:
                row[spp]["achieved_over_ideal"] = rmse / ideal_1spp if ideal_1spp > 0 else None
            else:
                images[rname] = (runs[0]["image"], cost)
        result["renderers"][rname] = row
    # The object's error against full detail rendered the same way (the same spp and seeds):
    # free of the reference's own noise, which dominates `object` for objects of a few pixels.
    for spp in sorted({1, a.spp}):
        v = np.array(result["renderers"]["volumetric"][spp].pop("object_sums"))
        t = np.array(result["renderers"]["traditional"][spp].pop("object_sums"))
        c = float(contribution.sum())
        result["renderers"]["volumetric"][spp]["object_vs_full"] = float((v.mean() - t.mean()) / c)
        result["renderers"]["volumetric"][spp]["object_vs_full_se"] = float(
            np.sqrt(v.var(ddof=1) / len(v) + t.var(ddof=1) / len(t)) / c)
    images["reference"] = ref
    images["box"] = crop_box(near, w, h)
    return result, images


def crop_box(mask, w, h):
    """Rows and columns around `mask`, padded, at least a quarter of the frame, 4:3."""
    ys, xs = np.nonzero(mask)
    if len(ys) == 0 or mask.mean() > 0.25:
        return 0, h, 0, w
    cy, cx = (ys.min() + ys.max() + 1) / 2, (xs.min() + xs.max() + 1) / 2
    half_w = max((xs.max() - xs.min() + 1) * 0.75, (ys.max() - ys.min() + 1) * 0.75 * 4 / 3, w / 8)
    half_h = half_w * 3 / 4
    x0 = int(np.clip(round(cx - half_w), 0, w - 2 * half_w))
    y0 = int(np.clip(round(cy - half_h), 0, h - 2 * half_h))
    return y0, y0 + int(round(2 * half_h)), x0, x0 + int(round(2 * half_w))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--amalgam", default=os.path.join(ROOT, "build", "amalgam"))
    ap.add_argument("--views", default=",".join(VIEWS))
    ap.add_argument("--factor", type=int, default=8)
    ap.add_argument("--ref-spp", type=int, default=4, help="samples per sub-pixel of the reference")
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--footprint", type=float, default=1.0, help="cell size in cone widths")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--cache", default=os.path.join(ROOT, "out", "volumetric-eval"))
    ap.add_argument("--json")
    ap.add_argument("--doc", help="write DIR/results.md, results.json and views.png (docs/volumetric)")
    ap.add_argument("extra", nargs="*", help="more options for the volumetric renderer")
    a = ap.parse_args()
    cache = Cache(a.cache)
    results = []
    figures = {}
    print("| view | obj px | renderer | spp | RMSE | bias | bias vs cone ref | sd | worst tile | "
          "frame | object | HF | tests/ray (object) | ns/sample | achieved/ideal |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name in a.views.split(","):
        r, images = evaluate(a, name, cache)
        results.append(r)
        figures[name] = images
        for rname, row in r["renderers"].items():
            for spp, m in row.items():
                ai = m.get("achieved_over_ideal")
                print(f"| {name} | {r['object_pixels']} | {rname} | {spp} | {m['rmse']:.4f} | "
                      f"{m['bias']:.4f} | {m['bias_vs_cone_ref']:.4f} | {m['sd']:.4f} | "
                      f"{100 * m['tile_worst']:+.2f} % | {100 * m['frame']:+.2f} % | "
                      f"{100 * m['object']:+.1f} % | {m['hf']:.2f} | "
                      f"{m['tests_object'] if m['tests_object'] is None else round(m['tests_object'], 1)} | "
                      f"{m['ns_per_sample']:.0f} | {'' if ai is None else f'{ai:.2f}'} |", flush=True)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(results, f, indent=1)
    if a.doc:
        write_doc(a, results, figures)


def machine():
    cpu = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip()
    return f"{cpu}, {os.cpu_count()} cores, {time.strftime('%Y-%m-%d')}, commit {commit}"


def verdict(ok):
    return "met" if ok else "**not met**"


def write_doc(a, results, figures):
    """docs/volumetric/results.md: the table and the targets' verdicts, computed here."""
    os.makedirs(a.doc, exist_ok=True)
    with open(os.path.join(a.doc, "results.json"), "w") as f:
        json.dump(results, f, indent=1)
    argv = " ".join(["/usr/bin/python3", "scripts/volumetric_eval.py"] +
                    [x if not x.startswith(ROOT) else os.path.relpath(x, ROOT) for x in sys.argv[1:]])
    L = ["<!-- written by scripts/volumetric_eval.py; do not edit -->",
         f"Measured by `{argv}` on {machine()}.",
         "",
         f"Stratified sampling, {a.spp} spp and 1 spp, seeds 1-3; reference: full detail at "
         f"{a.factor} x {a.factor} sub-pixels, {a.ref_spp} spp each; volumetric cell size "
         f"{a.footprint:g} cone width(s). Tiles: 32 x 32, mean luminance over the seeds. "
         "`object`: the error of the object's contribution (its pixels and its shadow, two pixels "
         "around), ± its standard error over the seeds; `object vs full detail`: the same against "
         "full detail rendered the same way (spp, seeds), free of the reference's own noise. HF: high-frequency "
         "energy over the reference's (the ideal prefilter's own in brackets). Tests per camera "
         "ray over the object's pixels, shadow rays included.",
         "",
         "| view | object px | renderer | worst tile | frame | object | object vs full detail | HF (ideal) | 1 spp RMSE / ideal | tests per ray (object) | ns per sample | bake s |",
         "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    checks = {"tiles": [], "frame": [], "hf": [], "ideal": [], "tests": []}
    for r in results:
        v = r["renderers"]["volumetric"][a.spp]
        t = r["renderers"]["traditional"][a.spp]
        one_v = r["renderers"]["volumetric"][1]
        for name, m, one in (("volumetric", v, one_v),
                             ("traditional", t, r["renderers"]["traditional"][1])):
            ai = one.get("achieved_over_ideal")
            bake = m.get("bake_s")
            to = m["tests_object"]
            vs = (f"{100 * m['object_vs_full']:+.1f} ± {100 * m['object_vs_full_se']:.1f} %"
                  if "object_vs_full" in m else "")
            L.append(f"| {r['view']} | {r['object_pixels']} | {name} | {100 * m['tile_worst']:+.2f} % | "
                     f"{100 * m['frame']:+.2f} % | {100 * m['object']:+.1f} ± {100 * m['object_se']:.1f} % | {vs} | "
                     f"{m['hf']:.2f} ({r['hf_ideal']:.2f}) | {'' if ai is None else f'{ai:.2f}'} | "
                     f"{'' if to is None else f'{to:.1f}'} | {m['ns_per_sample']:.0f} | "
                     f"{'' if bake is None else f'{bake:.2f}'} |")
        checks["tiles"].append((r["view"], abs(v["tile_worst"]) <= 0.03))
        checks["frame"].append((r["view"], abs(v["frame"]) <= 0.01))
        checks["hf"].append((r["view"], v["hf"] >= 0.8))
        if one_v.get("achieved_over_ideal") is not None:
            checks["ideal"].append((r["view"], one_v["achieved_over_ideal"] <= 1.5))
        if r["view"].startswith(("tuft", "tree")) and v["tests_object"] and t["tests_object"]:
            checks["tests"].append((r["view"], v["tests_object"] <= t["tests_object"] / 5))
    names = {"tiles": "every 32 x 32 tile within 3 %", "frame": "frame within 1 %",
             "hf": "high-frequency energy >= 0.8 of the reference's",
             "ideal": "1-spp error within 1.5x of the ideal bound's",
             "tests": "tests per camera ray <= 1/5 of full detail's (tuft and tree views)"}
    L += ["", "| target | verdict | views that miss it |", "|---|---|---|"]
    for k, rows in checks.items():
        miss = [v for v, ok in rows if not ok]
        L.append(f"| {names[k]} | {verdict(not miss)} | {', '.join(miss)} |")
    meadow = [r for r in results if r["view"] == "bias-meadow"]
    if meadow:
        w = meadow[0]["renderers"]["volumetric"][a.spp]["tile_worst"]
        L.append(f"| stop gate: bias-meadow's worst tile within 1.5 % (half the tile target) | "
                 f"{verdict(abs(w) <= 0.015)} | {100 * w:+.2f} % |")
    with open(os.path.join(a.doc, "results.md"), "w") as f:
        f.write("\n".join(L) + "\n")
    write_figure(results, figures, os.path.join(a.doc, "views.png"))


def write_figure(results, figures, out):
    """Per view (cropped around the object): the reference, one volumetric and one full-detail
    render at the same spp, and the tests per pixel of both on one log scale."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm
    names = [r["view"] for r in results]
    fig, axes = plt.subplots(len(names), 5, figsize=(13, 2.2 * len(names)), squeeze=False,
                             layout="constrained")
    cols = ["reference", "volumetric", "full detail", "tests, volumetric", "tests, full detail"]
    for i, name in enumerate(names):
        im = figures[name]
        vmax = max(float(im["volumetric"][1].max()), float(im["traditional"][1].max()), 1.0)
        y0, y1, x0, x1 = im["box"]
        panels = [p[y0:y1, x0:x1] for p in (im["reference"], im["volumetric"][0], im["traditional"][0],
                                            im["volumetric"][1], im["traditional"][1])]
        for j, p in enumerate(panels):
            ax = axes[i][j]
            if j < 3:
                ax.imshow(np.clip(p, 0, 1) ** (1 / 2.2))
            else:
                last = ax.imshow(np.maximum(p, 1.0), norm=LogNorm(1.0, vmax), cmap="magma")
            ax.set_xticks([]), ax.set_yticks([])
            if i == 0:
                ax.set_title(cols[j])
            if j == 0:
                ax.set_ylabel(name if (y1 - y0, x1 - x0) == im["reference"].shape[:2] else
                              f"{name}\n(crop {x1 - x0} x {y1 - y0})")
        fig.colorbar(last, ax=axes[i][3:].tolist(), shrink=0.8, label="tests per camera sample")
    tmp = out + ".tmp.png"
    fig.savefig(tmp, dpi=80)
    os.replace(tmp, out)


if __name__ == "__main__":
    main()
