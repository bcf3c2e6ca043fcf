#!/usr/bin/env python3
"""Splits the volumetric renderer's error against full detail by term of the light reaching what
the camera sees (docs/volumetric/bias-terms.md), to find which term holds the bias before the
model is changed.

Every row is one render of `amalgam render --renderer volumetric` with a light probe (the
environment variable AMALGAM_LIGHT_PROBE, src/amalgam/util/probe.h) against a converged
full-detail render (the traditional renderer, --ref-spp stratified samples) of the same scene
variant with the same probe where it applies to both (no-shadows):

- as is: the production estimator;
- sign: no hot spot (cells attenuate a shadow ray over their whole chord). Any correlation
  model of the camera and shadow paths can only brighten: a view still too bright here has its
  main error elsewhere;
- by occluder: shadow rays attenuated by the cells of the instance they leave from only, by the
  other instances' cells only, by the world cells only, by no cells (triangles met at full
  detail always occlude);
- unshadowed: both renderers without shadow rays (the shading of cells alone);
- swaps: camera rays through triangles with shadow rays from their hits through cells; camera
  rays through cells with shadow rays through triangles (from the drawn member's point on the
  camera ray, the mean depth of its segment: a point in space, not on a surface);
- bake: the cells' coverage baked with 8 and 16 lines per finest cell (4 by default);
- by light: each light alone, the sky at 1, 2, 4 and 16 samples (the reference's sky at 16);
- by receiver: the ground's albedo set to 0 in both renders splits the error exactly (direct
  light only) into what the foliage or object returns and what the ground returns.

Figures: frame = the luminance summed over the frame minus the reference's, over the
reference's; tiles = the same per 32 x 32 tile (the worst, signed); object (views of one
object) = the same sum over the object's contribution (the reference minus the view without
the object, in absolute value), as scripts/volumetric_eval.py; se = the frame's standard error
from the pixels' spread (an upper bound).

Usage: scripts/bias_terms.py [--amalgam build/amalgam] [--views NAME,...] [--doc docs/volumetric]
Needs Debian's python3-numpy (run with /usr/bin/python3). About an hour on 2 cores, cached in
out/bias-terms (a rebuilt renderer reads none of another's images).
"""

import argparse
import hashlib
import json
import math
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import pfm  # noqa: E402
from volumetric_eval import binary_hash, machine  # noqa: E402

LUM = np.array([0.2126, 0.7152, 0.0722])
SKY = [0.35, 0.45, 0.65]


def looking_down(target, distance, elevation_deg=35.0):
    """As scripts/volumetric_eval.py: object and ground only in a 30-degree frame."""
    e = math.radians(elevation_deg)
    eye = (target[0], target[1] + distance * math.sin(e), target[2] + distance * math.cos(e))
    return ["--eye", ",".join(f"{x:g}" for x in eye), "--look-at",
            ",".join(f"{x:g}" for x in target), "--fov", "30"]


# Probes of the volumetric renderer: (name, AMALGAM_LIGHT_PROBE, applies to the reference too).
TERMS = [
    ("as is", "", False),
    ("no hot spot", "no-hot-spot", False),
    ("own cells only", "no-other-cells,no-world-cells", False),
    ("other instances' cells only", "no-self-cells,no-world-cells", False),
    ("world cells only", "no-self-cells,no-other-cells", False),
    ("no cells in shadows", "no-self-cells,no-other-cells,no-world-cells", False),
    ("unshadowed (both)", "no-shadows", True),
    ("camera triangles, shadows cells", "camera-triangles", False),
    ("camera cells, shadows triangles", "shadow-triangles", False),
    ("bake 8 lines", "lines=8", False),
    ("bake 16 lines", "lines=16", False),
]
SHORT = ["as is", "no hot spot", "unshadowed (both)", "camera triangles, shadows cells",
         "camera cells, shadows triangles"]
# One object on open ground (no other instances' or world cells to split by occluder), and the
# forest's aerial view (its frame is the costliest): the terms without the split by occluder.
FEW = [t for t in TERMS if t[0] in SHORT or t[0] == "bake 8 lines"]

# name: (scene, view options, width, height, object view?, terms). The single objects at the
# pixel pitch of scripts/volumetric_eval.py (128 x 96, 30 degrees), the forest at that of
# 768 x 512. Samples per pixel (volumetric, reference) in SPP: an object of a few pixels needs
# many for its error to stand above the noise.
# The forest through the middle 384 x 256 of its 768 x 512 frame (the same pixel pitch: a
# vertical field of view of 2 atan(tan(20) / 2)); its aerial view from about 420 m, likewise the
# middle of a 30-degree frame of 768 x 512.
FOREST = ["--fov", "20.63"]
AERIAL = ["--eye", "0,400,120", "--look-at", "0,0,0", "--fov", "15.26"]
VIEWS = {
    "tree-40": ("scenes/volumetric/tree.json", looking_down((0, 3, 0), 40), 128, 96, True, FEW),
    "tree-150": ("scenes/volumetric/tree.json", looking_down((0, 3, 0), 150), 128, 96, True, FEW),
    "tree-400": ("scenes/volumetric/tree.json", looking_down((0, 3, 0), 400), 128, 96, True, FEW),
    "tuft-10": ("scenes/volumetric/tuft.json", looking_down((0, 0.2, 0), 10), 128, 96, True, FEW),
    "tuft-25": ("scenes/volumetric/tuft.json", looking_down((0, 0.2, 0), 25), 128, 96, True, FEW),
    "tuft-60": ("scenes/volumetric/tuft.json", looking_down((0, 0.2, 0), 60), 128, 96, True, FEW),
    "wuson-15": ("scenes/volumetric/wuson.json", looking_down((0, 0.4, 0), 15), 128, 96, True, FEW),
    "sphere-12": ("scenes/volumetric/sphere.json", looking_down((0, 0.5, 0), 12), 128, 96, True,
                  FEW),
    "forest": ("scenes/forest.json", FOREST, 384, 256, False, TERMS),
    "forest-aerial": ("scenes/forest.json", AERIAL, 384, 256, False, FEW),
    "crowd": ("tests/data/crowd.json", [], 64, 48, False, [t for t in TERMS if t[0] in SHORT]),
    "bias-meadow": ("tests/data/bias-meadow.json", [], 128, 96, False,
                    [t for t in TERMS if t[0] in SHORT]),
}
# Light variants (by light): the scene's lights; its first (the sun) alone; a constant sky of n
# samples alone; the sun and a sky of 2 samples.
SPP = {"forest": (4, 64), "forest-aerial": (4, 64), "crowd": (64, 1024), "bias-meadow": (16, 256)}
SINGLE_SPP = (64, 256)
LIGHTS_ALL = ["scene", "sun", "sky-1", "sky-2", "sky-4", "sky-16", "sun+sky-2"]
# (The forest's sky of 16 samples is left out: a 384 x 256 frame of 4 samples per pixel took
# the volumetric renderer more than 14 minutes on 2 cores.)
LIGHTS = {"tree-400": ["scene", "sun", "sky-1", "sky-2", "sky-16"], "forest": [x for x in LIGHTS_ALL if x != "sky-16"],
          "forest-aerial": ["scene", "sun", "sky-1", "sky-2"],
          "tuft-25": ["scene", "sun", "sky-2", "sky-16"], "wuson-15": ["scene", "sun", "sky-2", "sky-16"]}


def lum(img):
    return img @ LUM


def load_scene(path):
    with open(path) as f:
        text = "\n".join(line for line in f if not line.lstrip().startswith("//"))
    return json.loads(text)


def variant(scene_path, lights, black_ground=False, objects=True):
    """The scene file as a dict, its mesh paths absolute, with light variant `lights`, the ground
    ('soil') black, or without its meshes and instances."""
    s = load_scene(scene_path)
    base = os.path.dirname(os.path.abspath(scene_path))
    for m in s.get("meshes", []):
        if "file" in m:
            m["file"] = os.path.normpath(os.path.join(base, m["file"]))
    if not objects:
        s.pop("meshes", None)
        s.pop("instances", None)
    if black_ground:
        s.setdefault("materials", {})["soil"] = {"colour": [0, 0, 0]}
    if lights != "scene":
        sun = s["lights"][0]
        out = []
        for part in lights.split("+"):
            if part == "sun":
                out.append(sun)
            else:
                out.append({"type": "sky", "radiance": SKY, "samples": int(part.split("-")[1])})
        s["lights"] = out
    return s


class Renders:
    """Renders keyed by the binary, the scene's text, the options and the probe."""

    def __init__(self, amalgam, folder, threads):
        self.amalgam, self.folder, self.threads = amalgam, folder, threads
        os.makedirs(folder, exist_ok=True)
        self.seconds = 0.0

    def image(self, scene, args, probe="", amalgam=None):
        return self.image_and_stats(scene, args, probe, amalgam, stats=False)[0]

    def image_and_stats(self, scene, args, probe="", amalgam=None, stats=True):
        """The image and (with `stats`) the render's stats JSON, cached side by side."""
        amalgam = amalgam or self.amalgam
        text = json.dumps(scene, sort_keys=True)
        key = hashlib.sha1("\n".join([binary_hash(amalgam), text, " ".join(args),
                                      probe]).encode()).hexdigest()[:20]
        img = os.path.join(self.folder, key + ".pfm")
        st = os.path.join(self.folder, key + ".stats.json")
        if not os.path.exists(img) or (stats and not os.path.exists(st)):
            scene_file = os.path.join(self.folder, key + ".json")
            with open(scene_file, "w") as f:
                f.write(text)
            env = dict(os.environ)
            env.pop("AMALGAM_LIGHT_PROBE", None)
            if probe:
                env["AMALGAM_LIGHT_PROBE"] = probe
            t0 = time.time()
            subprocess.run([amalgam, "render", scene_file, "--quiet", "--threads",
                            str(self.threads), "--sampler", "stratified", "--out",
                            img + ".tmp.pfm"] + (["--stats", st + ".tmp"] if stats else []) +
                           args, check=True, env=env, stdout=subprocess.DEVNULL)
            self.seconds += time.time() - t0
            if stats:
                os.replace(st + ".tmp", st)
            os.replace(img + ".tmp.pfm", img)
            os.unlink(scene_file)
        if not stats:
            return pfm.read_pfm(img).astype(np.float64), None
        with open(st) as f:
            return pfm.read_pfm(img).astype(np.float64), json.load(f)


def tiles(l, t=32):
    H, W = l.shape
    return np.array([[l[y:y + t, x:x + t].sum() for x in range(0, W, t)] for y in range(0, H, t)])


def compare(vol, ref, norm):
    """Frame, worst tile and normalised sums of vol - ref (luminance)."""
    lv, lr = lum(vol), lum(ref)
    d = lv - lr
    tv, tr = tiles(lv), tiles(lr)
    ok = tr > 1e-6 * tr.max()
    rel = np.where(ok, (tv - tr) / np.where(ok, tr, 1), 0)
    worst = float(rel.flat[np.argmax(np.abs(rel))])
    return {"frame": float(d.sum() / lr.sum()), "tile": worst,
            "norm": float(d.sum() / norm),
            "se": float(d.std() * math.sqrt(d.size) / norm)}


def measure(a, r, name):
    scene_path, view, w, h, single, terms = VIEWS[name]
    scene_path = os.path.join(ROOT, scene_path)
    size = ["--width", str(w), "--height", str(h)] + view
    spp, ref_spp = SPP.get(name, SINGLE_SPP)
    ref_args = size + ["--renderer", "traditional", "--spp", str(ref_spp), "--seed", "11"]
    vol_args = size + ["--renderer", "volumetric", "--spp", str(spp)]
    rows = []

    def volumetric(scene, probe, amalgam):
        """The mean of the volumetric renders of seeds 1 .. --seeds (its tiles' noise falls with
        their number; the bias does not)."""
        return sum(r.image(scene, vol_args + ["--seed", str(k)], probe, amalgam)
                   for k in range(1, a.seeds + 1)) / a.seeds

    def row(term, lights, probe, both, split, amalgam=None):
        s = variant(scene_path, lights)
        # The reference's sky: 16 samples, whatever the probe's (its mean does not depend on it).
        ref_lights = lights.replace("sky-1", "sky-16").replace("sky-2", "sky-16").replace(
            "sky-4", "sky-16")
        sr = variant(scene_path, ref_lights)
        ref = r.image(sr, ref_args, probe if both else "")
        vol = volumetric(s, probe, amalgam)
        if single:
            empty = r.image(variant(scene_path, ref_lights, objects=False), ref_args,
                            probe if both else "")
            norm = float(np.abs(lum(ref) - lum(empty)).sum())
        else:
            norm = float(lum(ref).sum())
        m = compare(vol, ref, norm)
        m.update({"view": name, "term": term, "lights": lights, "probe": probe})
        if split:
            ref_b = r.image(variant(scene_path, ref_lights, black_ground=True), ref_args,
                            probe if both else "")
            vol_b = volumetric(variant(scene_path, lights, black_ground=True), probe, amalgam)
            m["foliage"] = float((lum(vol_b) - lum(ref_b)).sum() / norm)
            m["ground"] = float(((lum(vol) - lum(vol_b)) - (lum(ref) - lum(ref_b))).sum() / norm)
        rows.append(m)
        print(f"| {name} | {lights} | {term} | {100 * m['norm']:+.2f} % | {100 * m['se']:.2f} % | "
              f"{100 * m['frame']:+.2f} % | {100 * m['tile']:+.2f} % | "
              f"{fmt(m.get('foliage'))} | {fmt(m.get('ground'))} |", flush=True)

    if a.candidate:  # a candidate model (another build, or a probe switch): its rows only
        for lights in ["scene"] + [x for x in LIGHTS.get(name, []) if x in ("sun", "sky-2")]:
            row(f"candidate: {a.candidate_probe or 'as is'}", lights, a.candidate_probe, False,
                split=True, amalgam=a.candidate)
        return rows
    for term, probe, both in terms:
        row(term, "scene", probe, both, split=term in ("as is", "no hot spot", "unshadowed (both)",
                                                       "camera triangles, shadows cells"))
    for lights in LIGHTS.get(name, []):
        if lights != "scene":
            row("as is", lights, "", False, split=lights in ("sun", "sky-2"))
            if lights in ("sun", "sky-2"):
                row("no hot spot", lights, "no-hot-spot", False, split=False)
    return rows


def fmt(x):
    return "" if x is None else f"{100 * x:+.2f} %"


HEADER = ("| view | lights | term | error (object or frame) | se | frame | worst tile | "
          "foliage's share | ground's share |\n|---|---|---|---|---|---|---|---|---|")


def write_doc(a, rows, folder):
    with open(os.path.join(folder, "bias-terms.json"), "w") as f:
        json.dump(rows, f, indent=1)
    lines = [
        "# The volumetric renderer's error, term by term",
        "",
        "Generated by `scripts/bias_terms.py --doc docs/volumetric` (do not edit): "
        f"{machine()}; stratified samples per pixel, volumetric (seeds 1 .. {a.seeds}, averaged) / full-detail "
        f"reference (traditional renderer, seed 11): single objects {SINGLE_SPP[0]} / "
        f"{SINGLE_SPP[1]}, " + ", ".join(f"{k} {v[0]} / {v[1]}" for k, v in SPP.items()) + ".",
        "",
        "Each row is the volumetric renderer with one light probe (`AMALGAM_LIGHT_PROBE`, "
        "docs/volumetric.md) against full detail with the same lights (and, for `unshadowed`, "
        "without shadows too). **error**: the luminance summed over the frame minus the "
        "reference's, over the object's contribution (views of one object: the reference minus "
        "the view without it) or over the reference's frame (the rest); **se** its standard "
        "error (an upper bound, from the pixels' spread); **frame** over the reference's "
        "frame; **worst tile** the largest relative error of a 32 x 32 tile; **foliage's / "
        "ground's share**: the error split exactly by receiver (the ground's albedo set to 0 "
        "in both renders), in the unit of *error*. Lights: `scene` the scene's own (a sun and "
        "a fill light), `sun` its first alone, `sky-n` a constant sky of n samples alone (the "
        "reference's sky at 16), `sun+sky-2` both.",
        "",
        "Views (scene, pixels, view options): " + "; ".join(
            f"{v} `{VIEWS[v][0]}` {VIEWS[v][2]}x{VIEWS[v][3]} `{' '.join(VIEWS[v][1])}`"
            for v in dict.fromkeys(m["view"] for m in rows)) + ". The forest's two views are "
        "the middle 384 x 256 of a 768 x 512 frame, at its pixel pitch.",
        "",
        HEADER,
    ]
    for m in rows:
        lines.append(f"| {m['view']} | {m['lights']} | {m['term']} | {100 * m['norm']:+.2f} % | "
                     f"{100 * m['se']:.2f} % | {100 * m['frame']:+.2f} % | "
                     f"{100 * m['tile']:+.2f} % | {fmt(m.get('foliage'))} | "
                     f"{fmt(m.get('ground'))} |")
    lines += ["", "## Which term holds the bias", ""] + summary(rows)
    with open(os.path.join(folder, "bias-terms.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


def summary(rows):
    """Per view, the error as is and each term's part in it (the change when it is switched
    off or swapped), the largest named; then the first stop gate on the forests: too bright by
    more than 1.5 % of the frame with no hot spot at all?"""
    out = ["Per view (the scene's own lights), in the unit of *error*: the error as is; the hot "
           "spot's part (as is minus no hot spot); the shading of cells alone (unshadowed); "
           "shadows through cells from full-detail hits (camera triangles); the bake (8 lines "
           "minus 4); the sky's spread over its sample counts (largest minus smallest of sky-n, "
           "as is). The largest in magnitude of the first four parts is named.", "",
           "| view | as is | hot spot | unshadowed | camera triangles | bake | sky over n | "
           "largest |", "|---|---|---|---|---|---|---|---|"]
    views = list(dict.fromkeys(m["view"] for m in rows))
    for v in views:
        at = {(m["lights"], m["term"]): m["norm"] for m in rows if m["view"] == v}
        base = at.get(("scene", "as is"))
        if base is None:
            continue
        parts = {
            "hot spot": base - at[("scene", "no hot spot")] if ("scene", "no hot spot") in at else None,
            "unshadowed": at.get(("scene", "unshadowed (both)")),
            "camera triangles": at.get(("scene", "camera triangles, shadows cells")),
            "bake": (at[("scene", "bake 8 lines")] - base) if ("scene", "bake 8 lines") in at else None,
        }
        sky = [at[(l, "as is")] for l in ("sky-1", "sky-2", "sky-4", "sky-16") if (l, "as is") in at]
        named = {k: x for k, x in parts.items() if x is not None}
        largest = max(named, key=lambda k: abs(named[k])) if named else ""
        out.append(f"| {v} | {fmt(base)} | {fmt(parts['hot spot'])} | {fmt(parts['unshadowed'])} | "
                   f"{fmt(parts['camera triangles'])} | {fmt(parts['bake'])} | "
                   f"{fmt(max(sky) - min(sky)) if len(sky) > 1 else ''} | {largest} |")
    out += ["", "Stop gate 1 (the forests, frame, no hot spot at all, more than +1.5 % too bright "
            "means the main error lies outside any correlation model):", ""]
    for m in rows:
        if m["view"].startswith("forest") and m["term"] == "no hot spot":
            verdict = "too bright: outside correlation" if m["frame"] > 0.015 else \
                "not too bright: a correlation model is not ruled out"
            out.append(f"- {m['view']}, lights {m['lights']}: {fmt(m['frame'])} of the frame: "
                       f"{verdict}")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--amalgam", default=os.path.join(ROOT, "build", "amalgam"))
    ap.add_argument("--views", default=",".join(VIEWS))
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--cache", default=os.path.join(ROOT, "out", "bias-terms"))
    ap.add_argument("--doc", help="write DIR/bias-terms.md and bias-terms.json")
    ap.add_argument("--candidate", help="only the rows of a candidate model: this binary's "
                    "volumetric renderer (the references from --amalgam)")
    ap.add_argument("--candidate-probe", default="", help="with --candidate: its light probe")
    ap.add_argument("--seeds", type=int, default=1, help="average the volumetric renders of "
                    "seeds 1 .. N (default 1)")
    a = ap.parse_args()
    r = Renders(a.amalgam, a.cache, a.threads)
    print(HEADER, flush=True)
    rows = []
    for name in a.views.split(","):
        if name not in VIEWS:
            sys.exit(f"--views: unknown view '{name}' ({', '.join(VIEWS)})")
        rows += measure(a, r, name)
    print(f"render time {r.seconds:.0f} s", file=sys.stderr)
    if a.doc:
        write_doc(a, rows, a.doc)


if __name__ == "__main__":
    main()
