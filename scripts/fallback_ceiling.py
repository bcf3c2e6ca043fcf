#!/usr/bin/env python3
"""The ceiling of the fallback that keeps full detail for camera rays and prefilters only the
shadows (docs/volumetric/fallback-ceiling.md): full detail's time and error by ray kind on the
forest views of scripts/bias_terms.py, beside the volumetric renderer and the fallback itself.

Every configuration renders the same view with the same samples and seed, and is compared with
the converged full-detail reference that scripts/bias_terms.py uses (the traditional renderer,
64 stratified samples per pixel, seed 11; its noise adds about 1/16 of a 4-sample render's
variance to the RMSE):

- full detail (our tracer, and `--tracer embree`), with and without shadow rays (the probe
  `no-shadows`): the time camera rays take, and what shadow rays add;
- the volumetric renderer as is, and with the candidate `lit-share`;
- the fallback: camera rays through triangles, shadow rays from their hits through cells
  (the probe `camera-triangles`), as is and with `lit-share`.

What the fallback can at most buy at equal samples is full detail's time over its time without
shadows (shadows for free); its camera rays are full detail's, so its noise is full detail's,
and its bias (frame, worst 32 x 32 tile) is what prefiltered shadows add.

Usage: scripts/fallback_ceiling.py [--amalgam build/amalgam] [--ref-amalgam BIN]
       [--views forest,forest-aerial] [--spp 4] [--doc docs/volumetric]
Needs Debian's python3-numpy (run with /usr/bin/python3). Renders are cached in
out/fallback-ceiling keyed by the binary, the scene, the options and the probe (the reference
in out/bias-terms, keyed by --ref-amalgam's binary); timings come from each render's stats.
"""

import argparse
import json
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from bias_terms import SPP, VIEWS, Renders, compare, lum, variant  # noqa: E402
from volumetric_eval import machine  # noqa: E402

# name: (renderer, tracer, light probe)
CONFIGS = [
    ("full detail", "traditional", "amalgam", ""),
    ("full detail, no shadows", "traditional", "amalgam", "no-shadows"),
    ("Embree", "traditional", "embree", ""),
    ("Embree, no shadows", "traditional", "embree", "no-shadows"),
    ("volumetric", "volumetric", "amalgam", ""),
    ("volumetric, lit-share", "volumetric", "amalgam", "lit-share"),
    ("fallback: camera triangles, shadows cells", "volumetric", "amalgam", "camera-triangles"),
    ("fallback, lit-share", "volumetric", "amalgam", "camera-triangles,lit-share"),
]


def setup(stats):
    """Load, build and bake: the stats' time_s and the cells' and world cells' bakes."""
    t, v = stats["time_s"], stats.get("volumes") or {}
    return t["load"] + t["build"] + t["bake"] + v.get("bake_s", 0.0) + v.get("world_bake_s", 0.0)


def measure(a, name, refs, renders):
    scene_path, view, w, h, _, _ = VIEWS[name]
    scene = variant(os.path.join(ROOT, scene_path), "scene")
    size = ["--width", str(w), "--height", str(h)] + view
    ref_spp = SPP[name][1]
    ref = refs.image(scene, size + ["--renderer", "traditional", "--spp", str(ref_spp), "--seed",
                                    "11"])
    rows = []
    for label, renderer, tracer, probe in CONFIGS:
        runs = [renders.image_and_stats(scene, size + ["--renderer", renderer, "--tracer", tracer,
                                                       "--spp", str(a.spp), "--seed", str(k)],
                                        probe)
                for k in range(1, a.seeds + 1)]
        st = runs[0][1]
        times = [r[1]["time_s"] for r in runs]
        m = {"view": name, "config": label, "probe": probe, "spp": a.spp,
             "render_s": float(np.median([t["render"] for t in times])),
             "setup_s": float(np.median([setup(r[1]) for r in runs])),
             "rays": st["rays"],
             "tests": {k: (st["tests"] or {}).get(k) for k in ("primary", "shadow")}}
        if "no-shadows" not in probe:  # the reference has shadows: no error to compare
            # RMSE of one seed's render (the noise of one render plus its bias); frame and
            # tiles of the seeds' mean (their noise falls with the number of seeds).
            d = lum(runs[0][0]) - lum(ref)
            m.update(compare(sum(r[0] for r in runs) / len(runs), ref, float(lum(ref).sum())))
            m["rmse"] = float(math.sqrt(np.mean(d * d)))
        rows.append(m)
        print(f"{name:14s} {label:42s} render {m['render_s']:7.2f} s  set-up "
              f"{m['setup_s']:5.2f} s  {err(m)}", flush=True)
    return rows


def err(m):
    if "rmse" not in m:
        return "| | |"
    return (f"{m['rmse']:.4f} | {100 * m['frame']:+.2f} % | {100 * m['tile']:+.2f} %")


def view_summary(rows):
    """Full detail's time by ray kind and the fallback's ceiling, per view."""
    by = {m["config"]: m for m in rows}
    out = []
    for tracer, full, bare in (("our tracer", "full detail", "full detail, no shadows"),
                               ("Embree", "Embree", "Embree, no shadows")):
        t, t0 = by[full]["render_s"], by[bare]["render_s"]
        out.append(f"- {tracer}: camera rays {t0:.2f} s, shadow rays {t - t0:.2f} s "
                   f"({100 * (t - t0) / t:.0f} % of {t:.2f} s); shadows for free would buy at "
                   f"most **{t / t0:.2f}x** at equal samples.")
    for fb in ("fallback: camera triangles, shadows cells", "fallback, lit-share"):
        f = by[fb]
        full = by["full detail"]
        out.append(
            f"- {fb}: {f['render_s']:.2f} s against full detail's {full['render_s']:.2f} s "
            f"(**{full['render_s'] / f['render_s']:.2f}x**), RMSE {f['rmse']:.4f} against "
            f"{full['rmse']:.4f}, frame {100 * f['frame']:+.2f} %, worst tile "
            f"{100 * f['tile']:+.2f} % (full detail's own: {100 * full['frame']:+.2f} %, "
            f"{100 * full['tile']:+.2f} %).")
    return out


def write_doc(a, rows, folder):
    with open(os.path.join(folder, "fallback-ceiling.json"), "w") as f:
        json.dump(rows, f, indent=1)
    lines = [
        "# The fallback's ceiling: full detail's time and error by ray kind",
        "",
        f"Generated by `scripts/fallback_ceiling.py --doc docs/volumetric` (do not edit): "
        f"{machine()}; {a.threads} threads, {a.spp} stratified samples per pixel, seeds 1 .. "
        f"{a.seeds}, against the converged full-detail reference of scripts/bias_terms.py (64 samples, "
        "seed 11). Views as in [bias-terms.md](bias-terms.md): the middle 384 x 256 of a "
        "768 x 512 frame of `scenes/forest.json`, from the ground and from about 420 m.",
        "",
        "**render**: the stats' render time (wall clock, this machine; the median over the "
        "seeds); **set-up**: load, build and bake (the volumetric renderer's cells and world cells "
        "included); **tests per camera ray / per shadow ray**: the stats' counts over the rays "
        "of each kind (Embree counts none); **RMSE**: of the luminance per pixel of seed 1's "
        "render against the reference; **frame** and **worst tile**: the luminance of the "
        "seeds' mean summed over the frame or a 32 x 32 tile minus the reference's, over the "
        "reference's (none without shadows: the reference has them).",
        "",
        "| view | configuration | render | set-up | tests per camera ray | tests per shadow "
        "ray | RMSE | frame | worst tile |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for m in rows:
        per = {k: "" if m["tests"][k] is None else f"{m['tests'][k] / max(m['rays'][k], 1):.1f}"
               for k in ("primary", "shadow")}
        lines.append(f"| {m['view']} | {m['config']} | {m['render_s']:.2f} s | "
                     f"{m['setup_s']:.2f} s | {per['primary']} | {per['shadow']} | {err(m)} |")
    for v in dict.fromkeys(m["view"] for m in rows):
        lines += ["", f"## {v}", ""] + view_summary([m for m in rows if m["view"] == v])
    with open(os.path.join(folder, "fallback-ceiling.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--amalgam", default=os.path.join(ROOT, "build", "amalgam"))
    ap.add_argument("--ref-amalgam", help="the binary of the cached references (default "
                    "--amalgam)")
    ap.add_argument("--views", default="forest,forest-aerial")
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--seeds", type=int, default=3, help="renders per configuration (seeds 1 .. N)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--cache", default=os.path.join(ROOT, "out", "fallback-ceiling"))
    ap.add_argument("--ref-cache", default=os.path.join(ROOT, "out", "bias-terms"))
    ap.add_argument("--doc", help="write DIR/fallback-ceiling.md and fallback-ceiling.json")
    a = ap.parse_args()
    refs = Renders(a.ref_amalgam or a.amalgam, a.ref_cache, a.threads)
    renders = Renders(a.amalgam, a.cache, a.threads)
    rows = []
    for name in a.views.split(","):
        if name not in ("forest", "forest-aerial"):
            sys.exit(f"--views: unknown view '{name}' (forest, forest-aerial)")
        rows += measure(a, name, refs, renders)
    if a.doc:
        write_doc(a, rows, a.doc)


if __name__ == "__main__":
    main()
