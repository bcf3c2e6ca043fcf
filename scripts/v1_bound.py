#!/usr/bin/env python3
"""The ideal bound of level of detail at the real pixel pitch: for V1
(scenes/aerial-forest.json at 1920x1080, vfov 30) and the other views, the share of pixels
whose detail is below a pixel, and what scripts/lod_bound.py says an ideal prefiltering
renderer could gain at K = 0.5 and 1 (speed-up at equal cost per sample) and its bias floor.

A full 1920x1080 frame at F x F = 8 x 8 sub-pixels is 133 M sub-pixels, too slow to render on
2 cores; so V1 is measured on WINDOWS of the frame at the same pixel pitch: the scene's camera
turned toward a point of the frame (on its centre column), with fewer pixels and a field of
view such that the window is that part of the frame: tan(vfov_w / 2) = (h_w / H) tan(vfov / 2)
cos^2(beta), beta the angle of the window's centre from the frame's axis (cos^2: the
frame's pixels subtend less angle away from its axis; exact for a window at the centre).

For each view the script
1. renders the full-detail image at F x F sub-pixels per pixel, exactly as lod_bound.py does
   (traditional renderer, stratified sampler, --spp S per sub-pixel, seed 11, 2 threads), but
   to an EXR, so that the albedo layer comes too; its RGB is written to a PFM;
2. renders full detail at the view's own pixels with 16 stratified samples per pixel, seeds
   12 and 13: the target error is full detail's measured 16-spp RMSE, sqrt(mean((a - b)^2) / 2)
   (full detail is unbiased), free of the reference's own noise; the RMSE of each against the
   pixel-averaged sub-pixel image (F^2 S samples per pixel, the reference of lod_bound.py) is
   recorded beside it;
3. runs scripts/lod_bound.py --image on that PFM with --target = the measured 16-spp RMSE,
   and records what it prints (and its JSON);
4. measures the share of pixels whose detail is below a pixel (see `shares`).

The views (VIEWS): V1 in three 480x270 windows (a quarter of the frame's width and height)
on the centre column at rows 270, 540 and 810, also pooled into one row; a 240x135 window at
the centre at F = 8 and F = 16 (does the sub-pixel size change the bound?); scenes/forest.json
as a whole 768x512 frame; scenes/meadow.json in a 384x256 window at the centre of its 768x512
frame and in its top and bottom halves (768x256 windows, pooled: the whole frame). Times on
2 cores (AMD EPYC): a V1 480x270 window about 6 minutes, the 240x135 one 1.5 (F = 8) and 5.5
(F = 16), the forest 9 (--spp 2), a meadow 384x256 window 5.5 (--spp 2).

    /usr/bin/python3 scripts/v1_bound.py --views v1-centre,v1-upper,v1-lower
    /usr/bin/python3 scripts/v1_bound.py --views v1-small
    /usr/bin/python3 scripts/v1_bound.py --views v1-small --factor 16
    /usr/bin/python3 scripts/v1_bound.py --views forest --spp 2
    /usr/bin/python3 scripts/v1_bound.py --views meadow-centre --spp 2
    /usr/bin/python3 scripts/v1_bound.py --views meadow-top --spp 1
    /usr/bin/python3 scripts/v1_bound.py --views meadow-bottom --spp 1
    /usr/bin/python3 scripts/v1_bound.py --report      # only the markdown, from the results

Results are kept per view in docs/benchmark/ideal-bound.json (so that each view can be run on
its own) and the markdown docs/benchmark/ideal-bound.md is regenerated from all of them after
every run. A view measured at F other than 8 is stored as NAME-fF. Needs python3-numpy (hence
/usr/bin/python3 here); run from anywhere (it changes to the repository's root).
"""
import argparse
import datetime
import json
import math
import os
import platform
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from exr_layers import read_exr  # noqa: E402
import pfm  # noqa: E402

SOIL = (0.3, 0.22, 0.15)  # the ground of all three scenes
# name: scene, the full frame (W, H), the window (w, h) or None for the whole frame, the row of
# the window's centre in the full frame (pixels from the top), the ground albedo or None.
VIEWS = {
    "v1-centre": ("scenes/aerial-forest.json", (1920, 1080), (480, 270), 540, SOIL),
    "v1-upper": ("scenes/aerial-forest.json", (1920, 1080), (480, 270), 270, SOIL),
    "v1-lower": ("scenes/aerial-forest.json", (1920, 1080), (480, 270), 810, SOIL),
    "v1-small": ("scenes/aerial-forest.json", (1920, 1080), (240, 135), 540, SOIL),
    "forest": ("scenes/forest.json", (768, 512), None, None, SOIL),
    "meadow-centre": ("scenes/meadow.json", (768, 512), (384, 256), 256, None),
    "meadow-top": ("scenes/meadow.json", (768, 512), (768, 256), 128, None),
    "meadow-bottom": ("scenes/meadow.json", (768, 512), (768, 256), 384, None),
    "meadow": ("scenes/meadow.json", (768, 512), None, None, None),
}
# Windows reported together as well (same size; the MSEs pooled): name, members.
POOLS = [
    ("V1: v1-centre + v1-upper + v1-lower pooled", ("v1-centre", "v1-upper", "v1-lower")),
    ("meadow: top + bottom pooled (the whole frame)", ("meadow-top", "meadow-bottom")),
]
THRESHOLDS = (0.05, 0.1, 0.2)  # relative std of the sub-pixel luminance
MAIN_THRESHOLD = 0.1


def v3(a):
    return np.array(a, dtype=np.float64)


def window_view(scene_path, full, window, row):
    """The render options that show `window` pixels of the scene camera's `full` frame about
    its centre column and `row`: (options, description)."""
    cam = json.load(open(os.path.join(ROOT, scene_path)))["camera"]
    eye, at = v3(cam["position"]), v3(cam["look_at"])
    up = v3(cam.get("up", [0, 1, 0]))
    vfov = math.radians(cam.get("vfov", 45.0))
    W, H = full
    w, h = window
    f = (at - eye) / np.linalg.norm(at - eye)
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    t = math.tan(vfov / 2)
    sy = (1 - 2 * row / H) * t  # tangent-plane offset of the window's centre (row from the top)
    d = f + sy * u
    beta = math.atan(sy)
    fov = 2 * math.degrees(math.atan((h / H) * t * math.cos(beta) ** 2))
    target = eye + 1000.0 * d / np.linalg.norm(d)
    fmt = lambda a: ",".join(f"{x:.6g}" for x in a)  # noqa: E731
    opts = ["--eye", fmt(eye), "--look-at", fmt(target), "--up", fmt(up), "--fov", f"{fov:.6f}"]
    desc = (f"{w}x{h} window of the {W}x{H} frame (vfov {math.degrees(vfov):g}), centred on "
            f"row {row}, column {W // 2}: vfov {fov:.4f} deg, {math.degrees(beta):+.2f} deg "
            f"from the axis")
    return opts, desc


def instances_in_frame(scene_path, full, height=5.0):
    """(instances, instances whose point `height` m above their base projects into the scene
    camera's `full` frame) of a scene whose instances are all scatters: the placements of
    scatter_placements (src/amalgam/scene/instance_patterns.cpp) with amalgam's counter-based
    Sampler (src/amalgam/math/random.h), ported to numpy."""
    m1, m2, m3 = (np.uint64(x) for x in (0x9E3779B97F4A7C15, 0xBF58476D1CE4E5B9,
                                         0x94D049BB133111EB))

    def mix64(z):
        z = z + m1
        z = (z ^ (z >> np.uint64(30))) * m2
        z = (z ^ (z >> np.uint64(27))) * m3
        return z ^ (z >> np.uint64(31))

    def unit(key, d):  # Sampler(key).next() for dimension d
        bits = mix64(key ^ mix64(np.full_like(key, d)))
        return (bits >> np.uint64(40)).astype(np.float32) * np.float32(1 / 16777216)

    sc = json.load(open(os.path.join(ROOT, scene_path)))
    cam = sc["camera"]
    eye, at = v3(cam["position"]), v3(cam["look_at"])
    f = (at - eye) / np.linalg.norm(at - eye)
    r = np.cross(f, v3(cam.get("up", [0, 1, 0])))
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    t = math.tan(math.radians(cam.get("vfov", 45.0)) / 2)
    total = inside = 0
    with np.errstate(over="ignore"):
        for inst in sc.get("instances", []):
            s = inst["scatter"]
            n, radius = s["count"], s["radius"]
            c = v3(s.get("centre", s.get("center", [0, 0, 0])))
            key = mix64(np.uint64(s.get("seed", 0)) ^ mix64(np.arange(n, dtype=np.uint64)))
            rad = radius * np.sqrt(unit(key, 0).astype(np.float64))
            phi = 2 * np.pi * unit(key, 1).astype(np.float64)
            p = np.stack([c[0] + rad * np.cos(phi), np.full(n, c[1] + height),
                          c[2] + rad * np.sin(phi)], axis=1) - eye
            z = p @ f
            x, y = (p @ r) / z, (p @ u) / z
            total += n
            inside += int(np.sum((z > 0) & (np.abs(x) <= t * full[0] / full[1]) &
                                 (np.abs(y) <= t)))
    return total, inside


def run(cmd):
    print("+", " ".join(cmd), file=sys.stderr, flush=True)
    t0 = time.monotonic()
    subprocess.run(cmd, check=True)
    return time.monotonic() - t0


def shares(layers, f, ground):
    """The share of pixels whose detail is below a pixel, two ways, from the F x F sub-pixel
    render (each sub-pixel the mean of S samples):

    - photometric (any view): a pixel is 'sub-pixel' when the standard deviation of the
      luminance of its F^2 sub-pixels exceeds t times their mean (t = 0.05, 0.1, 0.2; 0.1 the
      headline). It counts every pixel where the image varies inside the pixel: fine detail,
      and also the edges of larger things. Also: the share of the image's within-pixel
      variance (sum over pixels of the sub-pixels' RGB variance, what prefiltering can remove)
      that the t = 0.1 pixels hold.
    - geometric (views with a uniform ground of known albedo, `ground`): a sub-pixel 'sees an
      object' when its mean albedo differs from the ground's (by > 1e-4 in a channel) and is
      not 0 (a miss); a pixel 'holds objects' when any of its sub-pixels does. On V1 every
      element of a tree but the trunks (leaves, needle sprays, twigs, branches up to 16 cm
      across) is below a pixel (0.28-0.53 m), so this is the share of pixels whose content is
      sub-pixel detail; 'mixed' are those that also have a sub-pixel of pure ground.
    """
    rgb = np.stack([layers["R"], layers["G"], layers["B"]], axis=-1).astype(np.float64)
    Hs, Ws = rgb.shape[:2]
    H, W = Hs // f, Ws // f
    lum = (0.2126 * rgb[..., 0] + 0.7152 * rgb[..., 1] + 0.0722 * rgb[..., 2])
    lum = lum.reshape(H, f, W, f)
    mean = lum.mean(axis=(1, 3))
    std = lum.std(axis=(1, 3))
    rel = std / np.maximum(mean, 1e-6)
    out = {f"photometric_t{t:g}": float(np.mean(rel > t)) for t in THRESHOLDS}
    var = rgb.reshape(H, f, W, f, 3).var(axis=(1, 3)).sum(axis=-1)
    mask = rel > MAIN_THRESHOLD
    out["variance_share_t0.1"] = float(var[mask].sum() / max(var.sum(), 1e-30))
    if ground is not None and "albedo.R" in layers:
        alb = np.stack([layers["albedo.R"], layers["albedo.G"], layers["albedo.B"]], axis=-1)
        is_ground = np.all(np.abs(alb - np.array(ground, dtype=np.float32)) < 1e-4, axis=-1)
        is_miss = np.all(alb == 0, axis=-1)
        obj = (~is_ground & ~is_miss).reshape(H, f, W, f)
        gnd = is_ground.reshape(H, f, W, f)
        holds = obj.any(axis=(1, 3))
        out["geometric_holds_objects"] = float(np.mean(holds))
        out["geometric_mixed"] = float(np.mean(holds & gnd.any(axis=(1, 3))))
        out["subpixels_on_objects"] = float(np.mean(obj))
    return out


def measure(name, a):
    scene, full, window, row, ground = VIEWS[name]
    f = a.factor
    if window is None:
        w, h = full
        view, desc = [], f"the whole {w}x{h} frame, the scene's camera"
    else:
        w, h = window
        view, desc = window_view(scene, full, window, row)
    res = {"view": name, "scene": scene, "description": desc, "width": w, "height": h,
           "factor": f, "spp_per_subpixel": a.spp, "view_options": view}
    with tempfile.TemporaryDirectory(dir=a.tmp) as tmp:
        hi = os.path.join(tmp, "hi.exr")
        hi_cmd = [a.amalgam, "render", scene, "--renderer", "traditional", "--sampler",
                  "stratified", "--width", str(w * f), "--height", str(h * f), "--spp",
                  str(a.spp), "--threads", str(a.threads), "--seed", "11", "--quiet", "--out",
                  hi, "--stats", os.path.join(tmp, "hi.json")] + view
        res["hi_command"] = " ".join(hi_cmd)
        res["hi_seconds"] = run(hi_cmd)
        res["hi_stats_time_s"] = json.load(open(os.path.join(tmp, "hi.json")))["time_s"]
        layers = read_exr(hi)
        rgb = np.stack([layers["R"], layers["G"], layers["B"]], axis=-1)
        hi_pfm = os.path.join(tmp, "hi.pfm")
        pfm.write_pfm(hi_pfm, rgb)
        ref = rgb.astype(np.float64).reshape(h, f, w, f, 3).mean(axis=(1, 3))
        res["shares"] = shares(layers, f, ground)
        del layers, rgb
        # Full detail at the view's pixels, 16 stratified samples, two other seeds.
        fd, res["target_seconds"] = [], 0.0
        for seed in (12, 13):
            lo = os.path.join(tmp, f"fd16-{seed}.pfm")
            lo_cmd = [a.amalgam, "render", scene, "--renderer", "traditional", "--sampler",
                      "stratified", "--width", str(w), "--height", str(h), "--spp",
                      str(a.target_spp), "--threads", str(a.threads), "--seed", str(seed),
                      "--quiet", "--out", lo] + view
            res["target_command"] = " ".join(lo_cmd)
            res["target_seconds"] += run(lo_cmd)
            fd.append(pfm.read_pfm(lo).astype(np.float64))
        # Against the reference (its own noise included) and, free of it, from the two seeds:
        # E (a - b)^2 = 2 Var, full detail being unbiased. The latter is the target: the ideal
        # renderer's curves are measured against their own exact mean.
        res["target_rmse_vs_reference"] = [float(np.sqrt(np.mean((x - ref) ** 2))) for x in fd]
        res["target_rmse"] = float(np.sqrt(np.mean((fd[0] - fd[1]) ** 2) / 2))
        res["reference_mean"] = ref.mean(axis=(0, 1)).tolist()
        # The bound itself.
        bjson = os.path.join(tmp, "bound.json")
        b_cmd = [sys.executable, os.path.join(HERE, "lod_bound.py"), "--scene", scene,
                 "--image", hi_pfm, "--factor", str(f), "--footprints", a.footprints,
                 "--target-spp", str(a.target_spp), "--target", f"{res['target_rmse']:.6g}",
                 "--json", bjson]
        print("+", " ".join(b_cmd), file=sys.stderr, flush=True)
        t0 = time.monotonic()
        p = subprocess.run(b_cmd, check=True, capture_output=True, text=True)
        res["bound_seconds"] = time.monotonic() - t0
        res["lod_bound_output"] = p.stdout
        print(p.stdout, flush=True)
        res["bound"] = json.load(open(bjson))
        # The same bound against the model's own 16-spp RMSE (no within-sub-pixel noise).
        sys.path.insert(0, HERE)
        import lod_bound  # noqa: E402

        rows = res["bound"]["rows"]
        ns = [int(n) for n in rows[0]["rmse"]]
        model_target = rows[0]["rmse"][str(a.target_spp)]
        res["model_target_rmse"] = model_target
        for r in rows:
            curve = {int(n): v for n, v in r["rmse"].items()}
            need, at_most = lod_bound.spp_to_reach(curve, ns, model_target)
            r["speedup_bound_model_target"] = (a.target_spp / need) if need else None
            r["at_most_model_target"] = at_most
    return res


def fmt_speed(r, target, key="speedup_bound", most="at_most"):
    v = r.get(key)
    if v is None:
        return "never (floor above it)" if r["floor"] >= target else "not by 16 spp"
    return f"{'>= ' if r.get(most) else ''}{v:.1f}x"


def pooled(results, views, name):
    """One result for `views` together (windows of equal size): the MSEs of every curve, floor
    and target are averaged over the windows, as over the pixels of one image made of them,
    and the shares likewise; the speed-ups are read off the pooled curves."""
    sys.path.insert(0, HERE)
    import lod_bound  # noqa: E402

    rs = [results[v] for v in views]
    if len({(r["width"], r["height"], r["factor"]) for r in rs}) != 1:
        raise ValueError("pooled windows must have one size")
    rms = lambda xs: float(np.sqrt(np.mean(np.square(xs))))  # noqa: E731
    out = {k: rs[0][k] for k in ("width", "height", "factor", "spp_per_subpixel")}
    out["windows"] = len(rs)
    out["target_rmse"] = rms([r["target_rmse"] for r in rs])
    out["model_target_rmse"] = rms([r["model_target_rmse"] for r in rs])
    out["shares"] = {k: float(np.mean([r["shares"][k] for r in rs])) for k in rs[0]["shares"]}
    rows = []
    for i, row0 in enumerate(rs[0]["bound"]["rows"]):
        curve = {int(n): rms([r["bound"]["rows"][i]["rmse"][n] for r in rs])
                 for n in row0["rmse"]}
        row = {"K": row0["K"], "floor": rms([r["bound"]["rows"][i]["floor"] for r in rs]),
               "rmse": {str(n): v for n, v in curve.items()}}
        ns = sorted(curve)
        for tkey, skey, mkey in (("target_rmse", "speedup_bound", "at_most"),
                                 ("model_target_rmse", "speedup_bound_model_target",
                                  "at_most_model_target")):
            need, at_most = lod_bound.spp_to_reach(curve, ns, out[tkey])
            row[skey] = (16 / need) if need else None
            row[mkey] = at_most
        rows.append(row)
    out["bound"] = {"rows": rows}
    results[name] = out
    return name


def table(results, views):
    """The summary table's lines for `views`."""
    L = ["| view | pixels (F, spp/sub-pixel) | sub-pixel share: rel. std > 0.1 (0.05 / 0.2) "
         "| its share of within-pixel variance | pixels holding objects (mixed with ground) "
         "| target RMSE (16 spp) | K = 0.5: floor, speed-up (model) | K = 1: floor, "
         "speed-up (model) |", "|---|---|---|---|---|---|---|---|"]
    for v in views:
        r = results[v]
        s = r["shares"]
        rows = {row["K"]: row for row in r["bound"]["rows"]}
        geo = (f"{100 * s['geometric_holds_objects']:.0f} % ({100 * s['geometric_mixed']:.0f} %)"
               if "geometric_holds_objects" in s else "-")
        cells = []
        for k in (0.5, 1.0):
            row = rows.get(k)
            if row is None:
                cells.append("-")
                continue
            model = fmt_speed(row, r["model_target_rmse"], "speedup_bound_model_target",
                              "at_most_model_target")
            cells.append(f"{row['floor']:.4f}, **{fmt_speed(row, r['target_rmse'])}** ({model})")
        n = f"{r['windows']} x " if "windows" in r else ""
        L.append(f"| {v} | {n}{r['width']}x{r['height']} ({r['factor']}, {r['spp_per_subpixel']}) "
                 f"| {100 * s['photometric_t0.1']:.0f} % ({100 * s['photometric_t0.05']:.0f} / "
                 f"{100 * s['photometric_t0.2']:.0f} %) | {100 * s['variance_share_t0.1']:.0f} % "
                 f"| {geo} | {r['target_rmse']:.4f} | {cells[0]} | {cells[1]} |")
    return L


def verdicts(results, views):
    """Generated sentences: each view's bound against 8x, the model's optimism, and the
    sub-pixel size's effect where a view was measured at two factors."""
    L = []
    for v in views:
        r = results[v]
        rows = {row["K"]: row for row in r["bound"]["rows"]}
        parts = []
        for k in (0.5, 1.0):
            row = rows.get(k)
            if row is None:
                continue
            sp = row.get("speedup_bound")
            word = ("never reaches the target" if sp is None else
                    f"{fmt_speed(row, r['target_rmse'])}: "
                    + ("at least 8x" if sp >= 8 else "**below 8x**"))
            parts.append(f"K = {k:g} {word}")
        zero = rows.get(0.0)
        opt = ""
        if zero and zero.get("speedup_bound"):
            opt = (f"; the model's own full detail (K = 0) reaches that target with "
                   f"{16 / zero['speedup_bound']:.1f} spp, i.e. the model is "
                   f"{zero['speedup_bound']:.1f}x optimistic about full detail's noise")
        L.append(f"- {v}: ideal bound at " + ", ".join(parts) + opt + ".")
    for v in views:
        f16 = f"{v}-f16"
        if f16 in results:
            a, b = results[v], results[f16]
            ra = {row["K"]: row for row in a["bound"]["rows"]}
            rb = {row["K"]: row for row in b["bound"]["rows"]}
            cells = [f"K = {k:g}: {fmt_speed(ra[k], a['target_rmse'])} at F = {a['factor']}, "
                     f"{fmt_speed(rb[k], b['target_rmse'])} at F = {b['factor']} (floors "
                     f"{ra[k]['floor']:.4f}, {rb[k]['floor']:.4f})" for k in (0.5, 1.0)
                     if k in ra and k in rb]
            L.append(f"- sub-pixel size, {v}: " + "; ".join(cells) + ".")
    return L


def report(results, path, a):
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                            capture_output=True, text=True).stdout.strip()
    cpu = "unknown CPU"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    order = [v for name in VIEWS for v in sorted(results)
             if v.split("-f")[0] == name and "superseded" not in results[v]]
    L = []
    L.append("# The ideal bound at the real pixel pitch")
    L.append("")
    L.append("Generated by `scripts/v1_bound.py` (do not edit by hand); the per-view data are in "
             "[ideal-bound.json](ideal-bound.json).")
    L.append("")
    L.append(f"- table written {datetime.datetime.now().strftime('%Y-%m-%d %H:%M')}, "
             f"commit {commit} (each view's own run: its `measured` line below)")
    L.append(f"- machine: {cpu}, {os.cpu_count()} cores, {platform.system()} "
             f"{platform.release()}; renders with 2 threads (wall-clock times below are on a "
             "machine that other jobs may have shared)")
    binaries = sorted({r.get("binary", "?") for r in results.values()})
    L.append(f"- binary: {', '.join(binaries)} (`build/amalgam`, a release build, with its "
             "modification time; a view measured before this was recorded shows `?`)")
    L.append("- commands: `scripts/v1_bound.py --views NAME[,NAME...]` per view (below), "
             "then `scripts/v1_bound.py --report`")
    L.append("")
    total, inside = instances_in_frame("scenes/aerial-forest.json", (1920, 1080))
    L.append("**V1** is `scenes/aerial-forest.json` at 1920x1080, vfov 30 (its `comment` says "
             f"what it holds): {total:,} trees, {inside:,} of them in the frame (a point 5 m "
             "above the base inside it; scatter_placements ported to numpy). Its full frame "
             "at 8 x 8 sub-pixels is too slow to reference on 2 cores, so it is measured on "
             "windows at the same pixel pitch: the same camera "
             "turned toward a point of the frame's centre column, with fewer pixels and the "
             "field of view that makes the window that part of the frame: tan(vfov_w / 2) = "
             "(h_w / H) tan(vfov / 2) cos^2(beta), beta the angle of the window's centre from "
             "the frame's axis (exact at the centre; off it, the frame's pixels are narrower by "
             "cos(beta) across and cos^2(beta) down, and the window matches the latter). The "
             "forest and the meadow are at 768x512, their cameras as in their files; the "
             "meadow's halves are windows of its frame in the same way.")
    L.append("")
    L.append("How to read it: `target` is full detail's **measured** RMSE at 16 stratified "
             "samples per pixel (from two seeds: sqrt(mean((a - b)^2) / 2), free of the "
             "reference's noise), which lod_bound.py is given as --target; its reference is "
             "the pixel-averaged F x F sub-pixel image. `bias floor` is the ideal renderer's "
             "RMSE at any number of samples (its blur). `speed-up` = 16 / the samples the "
             "ideal renderer at footprint K needs to reach `target` (log-log between measured "
             "points, as lod_bound.py reads it), at equal cost per sample; `(model)` is the "
             "same against the sub-pixel model's own 16-spp error, which lacks the noise "
             "inside a sub-pixel. `sub-pixel share`: the share of pixels whose F^2 sub-pixel "
             "luminances vary by a relative standard deviation above 0.1 (0.05 / 0.2 beside "
             "it), and, where the ground is a known "
             "colour, the share of pixels in which some sub-pixel sees an object (a tree: on "
             "V1 all its elements but trunks are below a pixel), and in brackets the share "
             "that also has a sub-pixel of bare ground. The photometric share counts every "
             "pixel whose image varies inside it, edges of things wider than a pixel included "
             "(the near grass blades of the meadow); `its share of within-pixel variance` is "
             "how much of the image's variance inside pixels (what prefiltering can remove) "
             "those pixels hold. With 1 sample per sub-pixel (the meadow's halves) the "
             "sub-pixel values are point samples, so the model's full detail lacks less of "
             "the real noise.")
    L.append("")
    main = [v for v in order if "superseded" not in results[v]]
    for name, members in POOLS:
        have = [v for v in members if v in results]
        if len(have) == len(members):
            main.insert(max(main.index(v) for v in have) + 1, pooled(results, have, name))
    L.extend(table(results, main))
    L.append("")
    L.extend(verdicts(results, main))
    old = [v for v in sorted(results) if "superseded" in results[v]]
    if old:
        v1a = [v for v in ("v1a-centre", "v1a-upper", "v1a-lower") if v in results]
        L.append("")
        L.append("### Views tried before V1 was fixed")
        L.append("")
        for note in sorted({results[v]["superseded"] for v in old}):
            L.append(f"- {', '.join(v for v in old if results[v]['superseded'] == note)}: "
                     f"{note}")
        L.append("")
        L.extend(table(results, old + ([pooled(results, v1a, "V1a: the three pooled")]
                                       if len(v1a) > 1 else [])))
    L.append("")
    L.append("## Each view")
    for v in order + old:
        r = results[v]
        L.append("")
        L.append(f"### {v}")
        L.append("")
        if "superseded" in r:
            L.append(f"- **{r['superseded']}**")
        L.append(f"- {r['scene']}: {r['description']}")
        L.append(f"- measured {r.get('date', '?')} at commit {r.get('commit', '?')}; "
                 f"`scripts/v1_bound.py --views {r['view']} --spp {r['spp_per_subpixel']} --factor "
                 f"{r['factor']}`")
        L.append(f"- the sub-pixel render ({r['hi_seconds']:.0f} s): `{r['hi_command']}` "
                 "(the temporary paths shown are the run's)")
        vs = " and ".join(f"{x:.4f}" for x in r["target_rmse_vs_reference"])
        L.append(f"- full detail at 16 spp, seeds 12 and 13 ({r['target_seconds']:.0f} s): "
                 f"RMSE {r['target_rmse']:.4f} from the two seeds (the target), {vs} against "
                 f"the reference (its own noise included); the sub-pixel model's own 16-spp "
                 f"RMSE: {r['model_target_rmse']:.4f}")
        L.append(f"- lod_bound.py on it ({r['bound_seconds']:.0f} s) printed:")
        L.append("")
        L.append("```")
        L.extend(r["lod_bound_output"].rstrip().splitlines())
        L.append("```")
    L.append("")
    with open(path, "w") as f:
        f.write("\n".join(L))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--views", default="", help="comma-separated: " + ", ".join(VIEWS))
    ap.add_argument("--report", action="store_true", help="only rewrite the markdown")
    ap.add_argument("--amalgam", default="build/amalgam")
    ap.add_argument("--factor", type=int, default=8)
    ap.add_argument("--spp", type=int, default=4, help="samples per sub-pixel")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--target-spp", type=int, default=16)
    ap.add_argument("--footprints", default="0.5,1,2")
    ap.add_argument("--results", default="docs/benchmark/ideal-bound.json")
    ap.add_argument("--doc", default="docs/benchmark/ideal-bound.md")
    ap.add_argument("--tmp", default=None, help="where the temporary images go")
    a = ap.parse_args()
    os.chdir(ROOT)
    results = json.load(open(a.results)) if os.path.exists(a.results) else {}
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    for v in [x for x in a.views.split(",") if x]:
        if v not in VIEWS:
            sys.exit(f"unknown view {v} (views: {', '.join(VIEWS)})")
        t0 = time.monotonic()
        r = measure(v, a)
        r["seconds"] = time.monotonic() - t0
        r["date"] = datetime.date.today().isoformat()
        r["commit"] = commit
        st = os.stat(a.amalgam)
        r["binary"] = (f"{a.amalgam} of "
                       f"{datetime.datetime.fromtimestamp(st.st_mtime).strftime('%Y-%m-%d %H:%M')}"
                       f", {st.st_size} bytes")
        results[v if a.factor == 8 else f"{v}-f{a.factor}"] = r
        os.makedirs(os.path.dirname(a.results), exist_ok=True)
        with open(a.results, "w") as f:
            json.dump(results, f, indent=1)
        print(f"{v}: {r['seconds']:.0f} s in all; shares {r['shares']}", file=sys.stderr)
    if results:
        report(results, a.doc, a)
    print(f"wrote {a.doc}", file=sys.stderr)


if __name__ == "__main__":
    main()
