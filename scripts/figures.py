#!/usr/bin/python3
"""Figures in the README and docs that a script writes and a test re-measures.

A figure in a page is marked where it stands:

    <!-- fig:demo.tests.traditional.coarse -->80.9<!-- /fig -->     deterministic: a count,
                                                                    tests per ray, a level, an
                                                                    error of a seeded render
    <!-- fig~:qvc.time.traditional.spp4 -->0.38<!-- /fig -->        a timing: written by the
                                                                    same run, not compared

The marks do not show in rendered Markdown. Each key's first part names the run that measures
it (GROUPS below). `update` runs them (or reads their outputs) and rewrites every marked figure;
`check` runs them afresh into a temporary directory and fails, naming page, key, written and
measured value, when a deterministic figure differs, and on a key no run measures. Same seed,
same bytes on any thread count, so a count that differs means the text is stale.

Usage:
  figures.py check  [--amalgam BIN] [--only GROUP,...]
  figures.py update [--amalgam BIN] [--only GROUP,...] [--demo-dir DIR] [--qvc-dir DIR]
  figures.py fill FILE --qvc-csv CSV        (scripts/quality-vs-cost.sh: the figures of its page)

Groups: demo (the four renders of scripts/demo.sh: 480x360, 4 spp, about 10 s),
experiments (the names `amalgam experiment` takes), counts (docs/exact-counts.md and
docs/scene-format.md: a line traced, prisms rendered, the field loaded; about 5 s), embree
(docs/guide.md: the pixels where --tracer embree differs from the traditional renderer; needs
a build with Embree), field (docs/real-scenes.md: scenes/field.json
at 1024x768 and its far band at 512x384; about 20 s; update also rewrites docs/img/field.png),
paper (the verdict counts of docs/paper-reproduction.md, which
scripts/plots/regenerate-docs.sh writes from `amalgam experiment all`), yardstick (the
summary at the top of docs/yardstick.md of its sections that scripts/yardstick.sh writes: best
speed-ups and commits), volumetric (the cost of `--renderer volumetric` that docs/volumetric.md
quotes, read from docs/volumetric/results.md, which scripts/volumetric_eval.py writes; no
render), stamps
(each hand-written reading of a generated run names that run's commit or date: regenerating
the run without rewriting its reading fails the check), advise (`amalgam advise` on the field's
street and aerial views and the meadow: timings only, so `update --only advise` writes them
and `check` never compares them; about 4 minutes), pyexample (examples/quality_vs_cost.py
through the Python module, build/python or $AMALGAM_PYTHON; about 3 s), qvc (scripts/quality-vs-cost.sh, about
40 s; its generated table is compared too, timing columns left out).
"""

import argparse
import csv
import json
import math
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

MARK = re.compile(r"<!-- fig(~?):([A-Za-z0-9_.+-]+) -->(.*?)<!-- /fig -->", re.S)
DEMO_SIZE = ["--width", "480", "--height", "360", "--spp", "4"]
DEMO_RUNS = [(s, r) for s in ("coarse", "fine") for r in ("traditional", "scale-sensitive")]
# Columns of the quality-vs-cost tables that are timings (left out of the comparison).
QVC_TIMING_COLUMNS = {"render s", "traditional s at that RMSE", "ratio"}


def pages():
    return [ROOT / "README.md"] + sorted((ROOT / "docs").glob("*.md"))


def marks(text):
    """(timing, key, value) of every figure of a page, in order."""
    return [(m.group(1) == "~", m.group(2), m.group(3)) for m in MARK.finditer(text)]


def fill_text(text, values):
    """The page with every figure whose key is in values rewritten."""
    def sub(m):
        key = m.group(2)
        if key not in values:
            return m.group(0)
        return f"<!-- fig{m.group(1)}:{key} -->{values[key]}<!-- /fig -->"
    return MARK.sub(sub, text)


def group_of(key):
    return key.split(".", 1)[0]


# --- demo: the four renders of scripts/demo.sh ------------------------------------------------

def demo_render(amalgam, out):
    out.mkdir(parents=True, exist_ok=True)
    for scene, renderer in DEMO_RUNS:
        name = f"{renderer}-{scene}"
        subprocess.run([amalgam, "render", str(ROOT / f"scenes/demo-field-{scene}.json"),
                        "--renderer", renderer, *DEMO_SIZE, "--out", str(out / f"{name}.png"),
                        "--cost-image", str(out / f"{name}-cost.pfm"),
                        "--level-image", str(out / f"{name}-level.pfm"),
                        "--stats", str(out / f"{name}.json"), "--quiet"], check=True)


def exp10(x):
    """1.6·10^10 as the README writes it."""
    e = len(str(int(x))) - 1
    return f"{x / 10 ** e:.1f}·10^{e}"


def demo_values(out):
    import numpy as np
    import pfm
    v = {}
    tris = {}
    levels = []
    for scene, renderer in DEMO_RUNS:
        st = json.loads((out / f"{renderer}-{scene}.json").read_text())
        v[f"demo.tests.{renderer}.{scene}"] = f"{st['per_primary_ray']['mean']:.1f}"
        tris[scene] = st["scene"]["primitives"]
        if renderer == "scale-sensitive":
            lv = pfm.read_pfm(out / f"{renderer}-{scene}-level.pfm")[:, :, 0]
            levels.append(np.rint(lv[lv >= 0]))
    for scene, n in tris.items():
        v[f"demo.triangles.{scene}"] = exp10(n)
    v["demo.growth"] = f"{tris['fine'] / tris['coarse']:.0f}x"
    rendered = np.concatenate(levels)
    v["demo.levels"] = f"{int(rendered.min())}-{int(rendered.max())}"
    return v


# --- experiments: the names `amalgam experiment` takes ----------------------------------------

def experiment_values(amalgam):
    text = subprocess.run([amalgam, "experiment", "--help"], check=True, capture_output=True,
                          text=True).stdout
    names = re.search(r"one of: ([a-zA-Z, -]+)", text).group(1).split(", ")
    return {"experiments.count": str(len(names))}


# --- counts: docs/exact-counts.md, "Exact counts, measured" --------------------------------

def stats_of(amalgam, tmp, *args):
    out = subprocess.run([amalgam, "render", *args, "--out", str(tmp / "counts.png"),
                          "--stats", "-", "--quiet"], check=True, capture_output=True,
                         text=True).stdout
    return json.loads(out)


def counts_values(amalgam, tmp):
    tr = json.loads(subprocess.run([amalgam, "trace", "builtin:line", "--set", "n=3", "--set",
                                    "depth=6", "--renderer", "traditional"], check=True,
                                   capture_output=True, text=True).stdout)
    v = {"counts.line.primary": str(tr["tests"]["primary"]),
         "counts.line.shadow": str(tr["tests"]["shadow"])}
    small = ["--width", "128", "--height", "128", "--spp", "1"]
    for depth in (6, 12):
        st = stats_of(amalgam, tmp, "builtin:prisms", "--set", f"depth={depth}", "--level", "4",
                      *small)
        v[f"counts.level4.{depth}"] = f"{st['per_primary_ray']['mean']:.5f}"
        v[f"counts.P.{depth}"] = (f"{st['scene']['primitives']:,}".replace(",", " ")
                                  if depth == 6 else exp10(st["scene"]["primitives"]))
        st = stats_of(amalgam, tmp, "builtin:prisms", "--set", f"depth={depth}",
                      "--renderer", "traditional", *small)
        v[f"counts.traditional.{depth}"] = f"{st['per_primary_ray']['mean']:.1f}"
    for depth in (11, 12):
        st = stats_of(amalgam, tmp, "builtin:prisms", "--set", f"depth={depth}", "--set",
                      "view=corner", "--width", "512", "--height", "512", "--spp", "4")
        v[f"counts.corner.{depth}"] = f"{st['per_primary_ray']['mean']:.1f}"
        v[f"counts.corner.P.{depth}"] = exp10(st["scene"]["primitives"])
        v[f"counts.corner.time.{depth}"] = f"{st['time_s']['render']:.1f}"
        v[f"counts.corner.rss.{depth}"] = f"{st['peak_memory_bytes'] / 2 ** 20:.0f}"
    st = stats_of(amalgam, tmp, str(ROOT / "scenes/field.json"), "--width", "64", "--height",
                  "48", "--spp", "1")
    t = st["time_s"]
    v["counts.field.setup"] = f"{t['load'] + t['build'] + t['bake']:.2f}"
    v["counts.field.rss"] = f"{st['peak_memory_bytes'] / 2 ** 20:.0f}"
    v["counts.field.triangles"] = exp10(st["scene"]["primitives"])
    return v


# --- embree: where --tracer embree and the traditional renderer differ -----------------------

EMBREE_SCENES = {"fine": "scenes/demo-field-fine.json", "coarse": "scenes/demo-field-coarse.json",
                 "field": "scenes/field.json", "spider": "scenes/spider-field.json",
                 "grid": "scenes/wuson-grid.json", "spheres": "scenes/spheres.json",
                 "line": "builtin:line", "poisson": "builtin:poisson", "prisms": "builtin:prisms",
                 "wuson": "/usr/share/assimp/models/PLY/Wuson.ply"}


def sig2(x):
    """A non-negative figure to two significant digits, never in exponent form."""
    if x == 0:
        return "0"
    digits = max(0, 1 - int(math.floor(math.log10(x))))
    return f"{x:.{digits}f}"


def embree_values(amalgam, tmp):
    """The agreement of --tracer embree with the traditional renderer, 1 spp, linear PFM."""
    import numpy as np
    import pfm
    v = {}
    for key, scene in EMBREE_SCENES.items():
        for w, h in ((128, 96), (512, 384)):
            imgs = []
            for tracer in ("amalgam", "embree"):
                path = tmp / f"embree-{tracer}.pfm"
                src = scene if scene.startswith(("builtin:", "/")) else str(ROOT / scene)
                subprocess.run([amalgam, "render", src, "--renderer", "traditional", "--tracer",
                                tracer, "--width", str(w), "--height", str(h), "--spp", "1",
                                "--out", str(path), "--quiet"], check=True)
                imgs.append(pfm.read_pfm(path).astype(np.float64))
            delta = np.abs(imgs[0] - imgs[1]).max(axis=2)
            rmse = float(np.sqrt(np.mean((imgs[0] - imgs[1]) ** 2)))
            v[f"embree.rmse{w}.{key}"] = sig2(rmse)
            if w == 512:
                v[f"embree.over005.{key}"] = str(int((delta > 0.05).sum()))
                if key == "fine":
                    v["embree.pixels"] = str(int((delta > 0).sum()))
                    v["embree.pixels.visible"] = str(int((delta > 0.01).sum()))
                    v["embree.total"] = f"{delta.size:,}"
                    v["embree.rmse"] = f"{rmse:.4f}"
    return v


# --- paper: the verdicts of docs/paper-reproduction.md (written by regenerate-docs.sh) -------

def paper_values():
    """docs/exact-counts.md's summary of the report's verdict table: counts and the statements
    of each verdict other than "holds"."""
    rows, inside = [], False
    for line in (ROOT / "docs/paper-reproduction.md").read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.startswith("| statement | the paper says | verdict"):
            inside = True
        elif inside and not line.startswith("|"):
            break
        elif inside and not set(cells[0]) <= set("-"):
            rows.append((cells[0], cells[2]))
    kinds = {"holds": [], "holds with correction": [], "does not hold": []}
    other = []
    for name, verdict in rows:
        (kinds[verdict] if verdict in kinds else other).append(f"{name} ({verdict})"
                                                              if verdict not in kinds else name)
    v = {"paper.count": str(len(rows)), "paper.holds": str(len(kinds["holds"])),
         "paper.correction": str(len(kinds["holds with correction"])),
         "paper.not": str(len(kinds["does not hold"])), "paper.other": str(len(other))}
    v["paper.list.correction"] = "; ".join(kinds["holds with correction"]) or "none"
    v["paper.list.not"] = "; ".join(kinds["does not hold"]) or "none"
    v["paper.list.other"] = "; ".join(other) or "none"
    return v


# --- yardstick: the summary at the top of docs/yardstick.md (its sections: yardstick.sh) ----

# The page of the yardstick, one section per scene, each with its own generated part: between
# the markers named after the section (scripts/yardstick_report.py --section NAME), or for the
# field (street and aerial views) the unnamed ones (section None).
YARDSTICK_DOC = "docs/yardstick.md"
# summary key: (section of YARDSTICK_DOC, view)
YARDSTICK_PAGES = {"meadow": ("meadow", "street"),
                   "soft": ("soft", "aerial"),
                   "aerial": (None, "aerial"),
                   "street": (None, "street")}


def yardstick_section(section):
    """The generated text of one section of docs/yardstick.md, markers included."""
    from yardstick_report import generated, markers
    text = generated((ROOT / YARDSTICK_DOC).read_text(), section)
    if text is None:
        begin, end = markers(section)
        sys.exit(f"figures.py: {YARDSTICK_DOC} has no generated section "
                 f"{section or '(unnamed: the field)'}: exactly one {begin} before one {end}")
    return text


def yardstick_commit(section):
    """The commit a section's generated part was measured at ("Generated by `...` at commit X.")."""
    m = re.search(r"` at commit ([0-9a-f]+)\.", yardstick_section(section))
    if m is None:
        sys.exit(f"figures.py: {YARDSTICK_DOC}, section {section or '(unnamed: the field)'}: "
                 "no \"Generated by `...` at commit X.\" line")
    return m.group(1)


def yardstick_values():
    """Per section and view: the scale-sensitive curve with the largest speed-up over the
    traditional renderer at equal error, its speed-up, its ratio to Embree, and the section's
    commit; "never" when no scale-sensitive curve reaches that error."""
    v = {}
    for key, (name, view) in YARDSTICK_PAGES.items():
        text = yardstick_section(name)
        v[f"yardstick.{key}.commit"] = yardstick_commit(name)
        section = text[text.index(f"### {view} view"):]
        best = None
        for line in section[section.index("| curve |"):].splitlines()[2:]:
            if not line.startswith("|"):
                break
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if cells[0].startswith("scale-sensitive") and cells[2] != "-":
                speed = float(cells[2].rstrip("x"))
                if best is None or speed > best[1]:
                    best = (cells[0], speed, cells[4])
        if best is None:
            v[f"yardstick.{key}.best"] = "never reaches that error (bias)"
            v[f"yardstick.{key}.embree"] = "-"
        else:
            v[f"yardstick.{key}.best"] = f"{best[1]:.2f}x ({best[0]})"
            v[f"yardstick.{key}.embree"] = best[2]
    return v


# --- stamps: a hand-written reading names the run it reads --------------------------------

# The page whose speed summary scripts/bench.sh --update-docs writes (scripts/bench_report.py).
BENCH_SUMMARY_DOC = "docs/performance.md"


def stamp_values():
    """The commit or date of each generated run that a hand-written reading comments on. A
    reading carries the stamp of the run it was written from; when the run is regenerated,
    the stamps differ and `check` says the reading must be rewritten."""
    v = {}
    # key: the section of docs/yardstick.md whose generated part the reading comments on (the
    # keys are named after the pages these sections were: yardstick-meadow.md, yardstick-soft.md)
    for key, section in (("yardstick", None), ("yardstick-meadow", "meadow"),
                         ("yardstick-soft", "soft")):
        v[f"stamps.{key}"] = yardstick_commit(section)
    summary = (ROOT / BENCH_SUMMARY_DOC).read_text()
    block = summary[summary.index("<!-- bench:begin"):summary.index("<!-- bench:end")]
    v["stamps.bench"] = re.search(r"date (\d{4}-\d\d-\d\d)", block).group(1)
    return v


# --- volumetric: what --renderer volumetric costs, from docs/volumetric/results.md ----------

VOLUMETRIC_RESULTS = "docs/volumetric/results.md"


def volumetric_values():
    """Per view of the table scripts/volumetric_eval.py writes: time per sample and tests per
    camera ray of the volumetric renderer beside full detail's (the traditional renderer, same
    samples and seeds), the error of the object against full detail, the bake; and the run's
    machine, date and commit."""
    text = (ROOT / VOLUMETRIC_RESULTS).read_text()
    m = re.search(r"^Measured by `[^`]*` on (.+)\.$", text, re.M)
    if m is None:
        sys.exit(f"figures.py: {VOLUMETRIC_RESULTS}: no \"Measured by `...` on ...\" line")
    v = {"volumetric.stamp": m.group(1)}
    rows, header = {}, None
    for line in text.splitlines():
        if not line.startswith("|"):
            if header is not None:
                break
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if header is None:
            if cells[:3] != ["view", "object px", "renderer"]:
                continue
            header = cells
        elif not set(cells[0]) <= set("-:"):
            rows[(cells[0], cells[2])] = dict(zip(header, cells))
    if not rows:
        sys.exit(f"figures.py: {VOLUMETRIC_RESULTS}: no table starting | view | object px | renderer |")
    objects = []  # the views of single objects: (time ratio, tests ratio)
    for (view, renderer), vol in rows.items():
        full = rows.get((view, "traditional"))
        if renderer != "volumetric" or full is None:
            continue
        tv, tf = float(vol["ns per sample"]), float(full["ns per sample"])
        nv, nf = float(vol["tests per ray (object)"]), float(full["tests per ray (object)"])
        v[f"volumetric.{view}.px"] = vol["object px"]
        v[f"volumetric.{view}.time"] = f"{tv:,.0f} / {tf:,.0f} ns ({tv / tf:.2f}x)"
        v[f"volumetric.{view}.tests"] = f"{nv:.1f} / {nf:.1f} ({nv / nf:.2f}x)"
        v[f"volumetric.{view}.error"] = vol["object vs full detail"]
        v[f"volumetric.{view}.bake"] = vol["bake s"]
        v[f"volumetric.{view}.time-ratio"] = f"{tv / tf:.2f}x"
        if "meadow" not in view:
            objects.append((tv / tf, nv / nf))
    if objects:
        t, n = [x for x, _ in objects], [y for _, y in objects]
        v["volumetric.objects.time-range"] = f"{min(t):.2f}-{max(t):.2f}x"
        v["volumetric.objects.tests-range"] = f"{min(n):.2f}-{max(n):.2f}x"
    return v


# --- field: docs/real-scenes.md (scenes/field.json at 1024x768 and its far band) -----------

FIELD_RUNS = [("ss4", ["--footprint", "1", "--spp", "4"]), ("ss1", ["--footprint", "1", "--spp", "1"]),
              ("trad1", ["--renderer", "traditional", "--spp", "1"]),
              ("trad4", ["--renderer", "traditional", "--spp", "4"])]


def field_values(amalgam, tmp, image_out=None):
    import numpy as np
    import pfm
    field = str(ROOT / "scenes/field.json")
    v, st = {}, {}
    for name, args in FIELD_RUNS:
        out = tmp / f"field-{name}.pfm"
        st[name] = json.loads(subprocess.run(
            [amalgam, "render", field, "--width", "1024", "--height", "768", "--threads", "2",
             *args, "--out", str(out), "--stats", "-", "--quiet"], check=True,
            capture_output=True, text=True).stdout)
        t, p = st[name]["time_s"], st[name]["per_primary_ray"]
        v[f"field.{name}.setup"] = f"{t['load']:.2f} + {t['build'] + t['bake']:.2f}"
        v[f"field.{name}.render"] = f"{t['render']:.2f}"
        v[f"field.{name}.tests"] = f"{p['mean']:.1f} / {p['p50']:g} / {p['p99']:g}"
        v[f"field.{name}.primitive"] = f"{st[name]['tests']['primitive'] / 1e6:.2f} M"
        v[f"field.{name}.memory"] = f"{st[name]['peak_memory_bytes'] / 1e6:.0f}"
    sc = st["ss4"]["scene"]
    v["field.triangles"] = f"{sc['primitives']:,}"
    v["field.nodes"] = f"{sc['nodes'] / 1e6:.0f} million"
    v["field.levels"] = str(sc["levels"])
    c = json.loads(subprocess.run([amalgam, "compare", str(tmp / "field-ss4.pfm"),
                                   str(tmp / "field-trad4.pfm"), "--json"], check=True,
                                  capture_output=True, text=True).stdout)
    v["field.cmp.rmse"], v["field.cmp.psnr"], v["field.cmp.ssim"] = (
        f"{c['rmse']:.4f}", f"{c['psnr_db']:.1f}", f"{c['ssim']:.3f}")
    a, b = st["ss4"]["tests"], st["trad4"]["tests"]
    v["field.fewer.primitive"] = f"{100 * (1 - a['primitive'] / b['primitive']):.0f} %"
    v["field.fewer.total"] = f"{100 * (1 - a['total'] / b['total']):.0f} %"
    if image_out:
        subprocess.run([amalgam, "render", field, "--width", "1024", "--height", "768",
                        "--footprint", "1", "--spp", "4", "--out", str(image_out), "--quiet"],
                       check=True)
    # The far band (rows 174-214 of 512x384: ground and Wusons just below the horizon), 4 spp,
    # against the traditional renderer at 32 spp with a seed of its own.
    band = {}
    for name, args in [("trad", ["--renderer", "traditional", "--spp", "4"]),
                       ("ss", ["--footprint", "1", "--spp", "4"]),
                       ("ss-k4", ["--footprint", "4", "--spp", "4"]),
                       ("ref", ["--renderer", "traditional", "--spp", "32", "--seed", "9001"])]:
        out = tmp / f"band-{name}.pfm"
        subprocess.run([amalgam, "render", field, "--width", "512", "--height", "384", *args,
                        "--out", str(out), "--quiet"], check=True)
        band[name] = pfm.read_pfm(out).astype(np.float64)
    lum = np.array([0.2126, 0.7152, 0.0722])
    for name in ("trad", "ss", "ref"):
        v[f"field.band.{name}"] = f"{float((band[name][174:214] @ lum).mean()):.3f}"
    for name in ("trad", "ss", "ss-k4"):
        rmse = float(np.sqrt(np.mean((band[name] - band["ref"]) ** 2)))
        v[f"field.band.rmse.{name}"] = f"{rmse:.4f}"
    return v


# --- advise: `amalgam advise` on three views (timings: written by update, never compared) -----

ADVISE_VIEWS = {
    "street": ["scenes/field.json"],
    "aerial": ["scenes/field.json", "--eye", "0,260,420", "--look-at", "0,0,0", "--fov", "40"],
    "meadow": ["scenes/meadow.json"],
}


def advise_values(amalgam, tmp):
    import datetime
    import platform
    v = {}
    for view, args in ADVISE_VIEWS.items():
        args = [str(ROOT / args[0])] + args[1:]
        out = subprocess.run([amalgam, "advise", *args, "--json", "-"], check=True,
                             capture_output=True, text=True).stdout
        j = json.loads(out)
        names = {}
        for r in j["renderers"]:
            names[r["key"]] = r["name"]
            v[f"advise.{view}.{r['key']}"] = (f"{r['vs_full_detail']:.2f}x "
                                              f"({r['vs_full_detail_low']:.2f}-"
                                              f"{r['vs_full_detail_high']:.2f})")
        q = j["level_of_detail_vs_full_detail"]
        v[f"advise.{view}.lod"] = names[j["best_level_of_detail"]]
        v[f"advise.{view}.full"] = names[j["best_full_detail"]]
        v[f"advise.{view}.lod_vs_full"] = f"{q['value']:.2f}x ({q['low']:.2f}-{q['high']:.2f})"
        v[f"advise.{view}.verdict"] = j["verdict"]
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                            capture_output=True, text=True).stdout.strip() or "unknown"
    v["advise.stamp"] = (f"{platform.node()}, {os.cpu_count()} cores, "
                         f"{datetime.date.today().isoformat()}, commit {commit}")
    return v


# --- pyexample: examples/quality_vs_cost.py (the Python module) ------------------------------

def pyexample_values(amalgam, tmp):
    module = Path(os.environ.get("AMALGAM_PYTHON", Path(amalgam).resolve().parent / "python"))
    env = dict(os.environ, PYTHONPATH=str(module))
    text = subprocess.run([sys.executable, str(ROOT / "examples/quality_vs_cost.py"),
                           str(tmp / "quality_vs_cost.png")], env=env, check=True,
                          capture_output=True, text=True).stdout
    v = {}
    for m in re.finditer(r"footprint\s+([0-9.]+): +([0-9.]+) tests/sample, "
                         r"RMSE ([0-9.]+), SSIM ([0-9.]+)", text):
        k = m.group(1)
        v[f"pyexample.tests.{k}"], v[f"pyexample.rmse.{k}"], v[f"pyexample.ssim.{k}"] = \
            m.group(2), m.group(3), m.group(4)
    v["pyexample.tests.full"] = f"{float(re.search(r'full detail *: +([0-9.]+)', text).group(1)):.0f}"
    return v


# --- qvc: scripts/quality-vs-cost.sh ----------------------------------------------------------

def qvc_values(csv_path):
    """The figures the quality-vs-cost page quotes in prose, from its results.csv."""
    rows = {r["name"]: r for r in csv.DictReader(open(csv_path))}
    v = {}
    for name, r in rows.items():
        v[f"qvc.rmse.{name}"] = f"{float(r['rmse']):.3f}"
        v[f"qvc.tests.{name}"] = f"{float(r['tests_per_ray_mean']):.1f}"
        v[f"qvc.p50.{name}"] = r["tests_per_ray_p50"]
        v[f"qvc.p99.{name}"] = f"{int(float(r['tests_per_ray_p99'])):,}"
        v[f"qvc.primitive.{name}"] = f"{int(r['primitive_tests']) / 1e6:.2f} M"
        v[f"qvc.time.{name}"] = f"{float(r['render_s']):.2f}"
    return v


def qvc_run(amalgam, out):
    env = dict(os.environ, AMALGAM=amalgam, OUT=str(out), DOC=str(out / "doc.md"))
    subprocess.run(["bash", str(ROOT / "scripts/quality-vs-cost.sh")], env=env, check=True,
                   cwd=ROOT)
    return out / "results.csv", out / "doc.md"


def mask_timing_columns(text):
    """The page with the timing columns of its tables blanked."""
    lines = text.splitlines()
    masked, header = [], None
    for line in lines:
        if line.startswith("|"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if header is None:
                header = cells
            elif not all(set(c) <= set("-: ") for c in cells):
                cells = ["~" if i < len(header) and header[i] in QVC_TIMING_COLUMNS else c
                         for i, c in enumerate(cells)]
            masked.append("| " + " | ".join(cells) + " |")
        else:
            header = None
            masked.append(MARK.sub(lambda m: "~" if m.group(1) else m.group(0), line))
    return "\n".join(masked)


# --- check / update ---------------------------------------------------------------------------

def measure(groups, amalgam, tmp, demo_dir=None, qvc_dir=None, update_images=False):
    """Every figure of the groups, measured (or read from the given directories)."""
    values, qvc_doc = {}, None
    if "demo" in groups:
        d = Path(demo_dir) if demo_dir else tmp / "demo"
        if not demo_dir:
            demo_render(amalgam, d)
        values.update(demo_values(d))
    if "experiments" in groups:
        values.update(experiment_values(amalgam))
    if "pyexample" in groups:
        values.update(pyexample_values(amalgam, tmp))
    if "counts" in groups:
        values.update(counts_values(amalgam, tmp))
    if "advise" in groups:
        values.update(advise_values(amalgam, tmp))
    if "paper" in groups:
        values.update(paper_values())
    if "yardstick" in groups:
        values.update(yardstick_values())
    if "stamps" in groups:
        values.update(stamp_values())
    if "volumetric" in groups:
        values.update(volumetric_values())
    if "field" in groups:
        values.update(field_values(amalgam, tmp,
                                   ROOT / "docs/img/field.png" if update_images else None))
    if "embree" in groups:
        values.update(embree_values(amalgam, tmp))
    if "qvc" in groups:
        if qvc_dir:
            values.update(qvc_values(Path(qvc_dir) / "results.csv"))
        else:
            csv_path, qvc_doc = qvc_run(amalgam, tmp / "qvc")
            values.update(qvc_values(csv_path))
    return values, qvc_doc


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mode", choices=["check", "update", "fill"])
    ap.add_argument("file", nargs="?")
    ap.add_argument("--amalgam", default=os.environ.get("AMALGAM", str(ROOT / "build/amalgam")))
    ap.add_argument("--only", default="demo,experiments,counts,embree,field,paper,yardstick,stamps,"
                                      "volumetric,pyexample,qvc")
    ap.add_argument("--demo-dir")
    ap.add_argument("--qvc-dir")
    ap.add_argument("--qvc-csv")
    a = ap.parse_args()

    if a.mode == "fill":
        path = Path(a.file)
        path.write_text(fill_text(path.read_text(), qvc_values(a.qvc_csv)))
        return 0

    groups = set(a.only.split(","))
    known = {"demo", "experiments", "counts", "embree", "field", "paper", "yardstick", "stamps",
             "volumetric", "advise", "pyexample", "qvc"}
    if not groups <= known:
        sys.exit(f"figures.py: unknown group {sorted(groups - known)}; known: {sorted(known)}")
    with tempfile.TemporaryDirectory() as tmp:
        values, qvc_doc = measure(groups, a.amalgam, Path(tmp), a.demo_dir, a.qvc_dir,
                                  update_images=a.mode == "update")
        qvc_fresh = (fill_text(qvc_doc.read_text(), values) if qvc_doc else None)
    problems, checked = [], 0
    for page in pages():
        text = page.read_text()
        rel = page.relative_to(ROOT)
        if a.mode == "update":
            new = fill_text(text, values)
            if new != text:
                page.write_text(new)
                print(f"figures: rewrote {rel}")
            continue
        for timing, key, written in marks(text):
            if group_of(key) not in known:
                problems.append(f"{rel}: figure {key}: no run measures it")
            elif group_of(key) not in groups or timing:
                continue
            elif key not in values:
                problems.append(f"{rel}: figure {key}: no run measures it")
            else:
                checked += 1
                if values[key] != written:
                    problems.append(f"{rel}: figure {key}: the page says {written!r}, "
                                    f"a fresh run gives {values[key]!r}")
    if a.mode == "check" and qvc_fresh is not None:
        page = ROOT / "docs/quality-vs-cost.md"
        old = mask_timing_columns(page.read_text()).splitlines()
        new = mask_timing_columns(qvc_fresh).splitlines()
        for i, (o, n) in enumerate(zip(old, new)):
            if o != n:
                problems.append(f"docs/quality-vs-cost.md:{i + 1}: the page says {o!r}, "
                                f"a fresh run gives {n!r}")
        if len(old) != len(new):
            problems.append("docs/quality-vs-cost.md: a fresh run gives "
                            f"{len(new)} lines, the page has {len(old)}")
    if a.mode == "check":
        for p in problems:
            print(p, file=sys.stderr)
        print(f"figures: {checked} figures checked in groups {sorted(groups)}, "
              f"{len(problems)} stale", file=sys.stderr)
        if problems:
            print("figures: regenerate with scripts/demo.sh --update-docs, "
                  "scripts/quality-vs-cost.sh --update-docs or scripts/figures.py update",
                  file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
