#!/usr/bin/env bash
# Quality vs cost of amalgams on a real-mesh field.
#
#   scripts/quality-vs-cost.sh           full study (about 25 s on 2 cores): writes
#                                        out/quality-vs-cost/{results.csv, *.png} and
#                                        out/quality-vs-cost.md (a copy of the docs page with
#                                        its generated part rewritten); touches no docs
#   scripts/quality-vs-cost.sh --update-docs   the same into docs/quality-vs-cost/ and
#                                        docs/quality-vs-cost.md (regenerates the docs)
#   scripts/quality-vs-cost.sh --quick   smoke run (tiny images) into a temporary directory;
#                                        touches nothing under docs/ or out/
#
# What it does: renders a reference (traditional renderer, REF_SPP samples per pixel, its own
# seed), then, at WIDTH x HEIGHT,
#   - the traditional renderer at spp 1, 4, 16;
#   - the scale-sensitive renderer, stochastic and deterministic opacity, at spp = SPP for
#     every footprint K in KS, and at spp 1 and 16 for K = 1;
# and measures each image against the reference with `amalgam compare --json` (RMSE, PSNR,
# SSIM of linear luminance/RGB decoded from the PNGs), the render wall time (`time_s.render`)
# and the tests per primary ray (`per_primary_ray`, its shadow rays included) from `--stats`.
#
# Environment: AMALGAM (binary; default build/amalgam), SCENE (default scenes/field.json),
# WIDTH, HEIGHT (512 x 384), SPP (4), REF_SPP (32), KS ("0.5 1 2 4 8 16"), THREADS (all
# cores), OUT (out/quality-vs-cost; with --update-docs docs/quality-vs-cost), DOC
# (out/quality-vs-cost.md; with --update-docs docs/quality-vs-cost.md).
set -euo pipefail
cd "$(dirname "$0")/.."

AMALGAM=${AMALGAM:-build/amalgam}
SCENE=${SCENE:-scenes/field.json}
WIDTH=${WIDTH:-512}
HEIGHT=${HEIGHT:-384}
SPP=${SPP:-4}
REF_SPP=${REF_SPP:-32}
KS=${KS:-"0.5 1 2 4 8 16"}
THREADS=${THREADS:-0}
mode=${1:-}
case "$mode" in
  "" | --quick | --update-docs) ;;
  *) echo "usage: scripts/quality-vs-cost.sh [--quick | --update-docs]" >&2; exit 2 ;;
esac
if [[ "$mode" == --update-docs ]]; then
  OUT=${OUT:-docs/quality-vs-cost}
  DOC=${DOC:-docs/quality-vs-cost.md}
else
  OUT=${OUT:-out/quality-vs-cost}
  DOC=${DOC:-out/quality-vs-cost.md}
fi
REF_SEED=9001  # the reference's samples differ from every measured render's (seed 0)

if [[ "$mode" == --quick ]]; then
  WIDTH=64 HEIGHT=48 REF_SPP=4 KS="1 4"
  OUT=$(mktemp -d)
  DOC=$OUT/doc.md
fi
[[ -x "$AMALGAM" ]] || { echo "quality-vs-cost: $AMALGAM not found (set AMALGAM or build first)" >&2; exit 1; }
command -v gnuplot >/dev/null || { echo "quality-vs-cost: gnuplot not found (apt-get install gnuplot-nox)" >&2; exit 1; }

mkdir -p "$OUT" "$(dirname "$DOC")"
# Outside the docs, the generated part is rewritten in a copy of the page.
[[ -f "$DOC" ]] || cp docs/quality-vs-cost.md "$DOC"
work=$(mktemp -d)  # every render and its stats; only the figures below are kept
trap 'rm -rf "$work"; [[ "$mode" == --quick ]] && rm -rf "$OUT"' EXIT
thread_args=()
[[ "$THREADS" != 0 ]] && thread_args=(--threads "$THREADS")

# render NAME ARGS...: one render into $work/NAME.png with its stats.
render() {
  local name=$1
  shift
  echo "quality-vs-cost: $name" >&2
  "$AMALGAM" render "$SCENE" --width "$WIDTH" --height "$HEIGHT" --quiet "${thread_args[@]}" \
    --out "$work/$name.png" --stats "$work/$name.json" "$@"
}

render reference --renderer traditional --spp "$REF_SPP" --seed "$REF_SEED"

runs=()
for s in 1 4 16; do
  render "trad-spp$s" --renderer traditional --spp "$s"
  runs+=("trad-spp$s traditional - - $s")
done
for k in $KS; do
  for op in stochastic deterministic; do
    render "$op-k$k-spp$SPP" --opacity "$op" --footprint "$k" --spp "$SPP"
    runs+=("$op-k$k-spp$SPP scale-sensitive $op $k $SPP")
  done
done
for s in 1 16; do
  [[ $s == "$SPP" ]] && continue
  for op in stochastic deterministic; do
    render "$op-k1-spp$s" --opacity "$op" --footprint 1 --spp "$s"
    runs+=("$op-k1-spp$s scale-sensitive $op 1 $s")
  done
done

csv=$OUT/results.csv
echo "name,renderer,opacity,footprint,spp,render_s,tests_per_ray_mean,tests_per_ray_p50,tests_per_ray_p99,primitive_tests,total_tests,rmse,psnr_db,ssim" >"$csv"
for r in "${runs[@]}"; do
  read -r name renderer opacity k s <<<"$r"
  cmp=$("$AMALGAM" compare "$work/$name.png" "$work/reference.png" --json)
  python3 - "$work/$name.json" "$cmp" "$name" "$renderer" "$opacity" "$k" "$s" >>"$csv" <<'PY'
import json, sys
st = json.load(open(sys.argv[1]))
c = json.loads(sys.argv[2])
name, renderer, opacity, k, s = sys.argv[3:8]
p = st["per_primary_ray"]
print(",".join([name, renderer, opacity, k, s, "%.3f" % st["time_s"]["render"],
                "%.2f" % p["mean"], "%g" % p["p50"], "%g" % p["p99"],
                "%d" % st["tests"]["primitive"], "%d" % st["tests"]["total"],
                "%.5f" % c["rmse"], "%.2f" % c["psnr_db"], "%.4f" % c["ssim"]]))
PY
done

# The images shown side by side, and an error image of the K = 1 stochastic render.
cp "$work/reference.png" "$OUT/reference.png"
cp "$work/stochastic-k1-spp$SPP.png" "$OUT/stochastic-k1.png"
cp "$work/trad-spp$SPP.png" "$OUT/traditional.png"
if [[ -f "$work/stochastic-k4-spp$SPP.png" ]]; then
  cp "$work/stochastic-k4-spp$SPP.png" "$OUT/stochastic-k4.png"
fi
cp "$work/deterministic-k1-spp$SPP.png" "$OUT/deterministic-k1.png"
"$AMALGAM" compare "$work/stochastic-k1-spp$SPP.png" "$work/reference.png" \
  --error-image "$OUT/error-stochastic-k1.png" >/dev/null
"$AMALGAM" compare "$work/trad-spp$SPP.png" "$work/reference.png" \
  --error-image "$OUT/error-traditional.png" >/dev/null

# Plots: error vs render time, and error and tests per ray vs K.
dat=$work/plot
python3 - "$csv" "$dat" "$SPP" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
base, spp = sys.argv[2], sys.argv[3]
def write(name, sel, cols):
    with open(f"{base}-{name}.dat", "w") as f:
        for r in sel:
            f.write(" ".join(r[c] for c in cols) + "\n")
trad = sorted([r for r in rows if r["renderer"] == "traditional"], key=lambda r: int(r["spp"]))
write("trad-time", trad, ["render_s", "rmse", "spp"])
for op in ("stochastic", "deterministic"):
    k1 = sorted([r for r in rows if r["opacity"] == op and r["footprint"] == "1"],
                key=lambda r: int(r["spp"]))
    write(f"{op}-k1-time", k1, ["render_s", "rmse", "spp"])
    ks = sorted([r for r in rows if r["opacity"] == op and r["spp"] == spp],
                key=lambda r: float(r["footprint"]))
    write(f"{op}-k-time", ks, ["render_s", "rmse", "footprint"])
    write(f"{op}-k", ks, ["footprint", "rmse", "tests_per_ray_mean", "render_s"])
t = [r for r in trad if r["spp"] == spp][0]
with open(f"{base}-trad-k.dat", "w") as f:
    for k in ("0.35", "23"):
        f.write(f"{k} {t['rmse']} {t['tests_per_ray_mean']} {t['render_s']}\n")
PY
gnuplot <<EOF
set terminal pngcairo size 1400,560 font ",11"
set output "$OUT/quality-vs-cost.png"
set multiplot layout 1,2
set grid
set key top right
set logscale xy
set title "Error vs render time ($WIDTH x $HEIGHT, reference: traditional $REF_SPP spp)"
set xlabel "render wall time (s, 2 threads, shared machine)"
set ylabel "RMSE vs reference (linear RGB)"
plot "$dat-trad-time.dat" u 1:2 w lp pt 7 lw 2 lc rgb "black" t "traditional, spp 1/4/16", \
     "" u 1:2:(sprintf("%d",\$3)) w labels offset 1.2,0.6 notitle, \
     "$dat-stochastic-k1-time.dat" u 1:2 w lp pt 5 lw 2 lc rgb "#1f77b4" t "stochastic K=1, spp 1/4/16", \
     "$dat-deterministic-k1-time.dat" u 1:2 w lp pt 9 lw 2 lc rgb "#d62728" t "deterministic K=1, spp 1/4/16", \
     "$dat-stochastic-k-time.dat" u 1:2 w lp pt 4 dt 2 lc rgb "#1f77b4" t "stochastic, spp $SPP, K = 0.5..16", \
     "" u 1:2:(sprintf("K=%g",\$3)) w labels offset -1.5,-0.7 font ",9" tc rgb "#1f77b4" notitle, \
     "$dat-deterministic-k-time.dat" u 1:2 w lp pt 8 dt 2 lc rgb "#d62728" t "deterministic, spp $SPP, K = 0.5..16"
set title "Error and cost vs footprint K (spp $SPP)"
set logscale x 2
unset logscale y
set xrange [0.35:23]
set xlabel "footprint K (pixels)"
set ylabel "RMSE vs reference"
set y2label "tests per primary ray (with its shadow rays)"
set y2tics
set ytics nomirror
set key below
plot "$dat-stochastic-k.dat" u 1:2 w lp pt 5 lw 2 lc rgb "#1f77b4" t "RMSE stochastic", \
     "$dat-deterministic-k.dat" u 1:2 w lp pt 9 lw 2 lc rgb "#d62728" t "RMSE deterministic", \
     "$dat-trad-k.dat" u 1:2 w l lw 2 lc rgb "black" t "RMSE traditional", \
     "$dat-stochastic-k.dat" u 1:3 axes x1y2 w lp pt 4 dt 2 lc rgb "#1f77b4" t "tests/ray stochastic", \
     "$dat-deterministic-k.dat" u 1:3 axes x1y2 w lp pt 8 dt 2 lc rgb "#d62728" t "tests/ray deterministic", \
     "$dat-trad-k.dat" u 1:3 axes x1y2 w l dt 2 lc rgb "black" t "tests/ray traditional"
unset multiplot
EOF

# The generated part of the document: the table and the equal-error time ratios.
python3 - "$csv" "$DOC" "$SPP" "$REF_SPP" "$WIDTH" "$HEIGHT" "$SCENE" <<'PY'
import csv, math, os, sys
path, doc, spp, ref_spp, w, h, scene = sys.argv[1:8]
rows = list(csv.DictReader(open(path)))
L = ["<!-- BEGIN GENERATED by scripts/quality-vs-cost.sh: do not edit by hand -->", ""]
import platform, subprocess, datetime
commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip() or "unknown"
stamp = (f"{platform.node()}, {os.cpu_count()} cores, "
         f"{datetime.date.today().isoformat()}, commit {commit}")
L.append(f"Scene `{scene}`, {w} x {h}; reference: traditional renderer, {ref_spp} spp, seed 9001. "
         "Time = `time_s.render` (wall, 2 threads; measured on <!-- fig~:qvc.stamp -->"
         f"{stamp}<!-- /fig -->); tests per primary ray include its shadow rays. "
         "Every column but the times is exact for this seed and is re-measured by "
         "`scripts/figures.py check` (the `docs_figures` test).")
L.append("")
L.append("| renderer | opacity | K | spp | render s | tests/ray mean | p50 | p99 | primitive tests | RMSE | PSNR dB | SSIM |")
L.append("|---|---|---|---|---|---|---|---|---|---|---|---|")
for r in rows:
    L.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
        r["renderer"], r["opacity"], r["footprint"], r["spp"], r["render_s"],
        r["tests_per_ray_mean"], r["tests_per_ray_p50"], r["tests_per_ray_p99"],
        "{:,}".format(int(r["primitive_tests"])), r["rmse"], r["psnr_db"], r["ssim"]))
# Time the traditional renderer needs for the same error: log-log interpolation of its
# (time, RMSE) points over spp 1/4/16 (extrapolated beyond them, marked so).
trad = sorted([(float(r["rmse"]), float(r["render_s"])) for r in rows if r["renderer"] == "traditional"])
def trad_time(e):
    pts = sorted(trad, reverse=True)  # decreasing error
    if e >= pts[0][0]:  # no more than 1 sample per pixel: its cheapest render is already better
        return pts[0][1], " (spp 1, already lower error)"
    for (e0, t0), (e1, t1) in zip(pts, pts[1:]):
        if e1 <= e <= e0:
            f = math.log(e0 / e) / math.log(e0 / e1)
            return t0 * (t1 / t0) ** f, ""
    (e0, t0), (e1, t1) = (pts[-2], pts[-1]) if e < pts[-1][0] else (pts[0], pts[1])
    f = math.log(e0 / e) / math.log(e0 / e1)
    return t0 * (t1 / t0) ** f, " (extrapolated)"
L.append("")
L.append("Equal-error time ratio: the traditional render time at the same RMSE (interpolated "
         "log-log between its spp 1/4/16 points; its spp 1 time when even spp 1 has a lower error) divided by the scale-sensitive render time; "
         "above 1 the amalgams pay off.")
L.append("")
L.append("| opacity | K | spp | RMSE | render s | traditional s at that RMSE | ratio |")
L.append("|---|---|---|---|---|---|---|")
for r in rows:
    if r["renderer"] != "scale-sensitive":
        continue
    t, note = trad_time(float(r["rmse"]))
    L.append("| %s | %s | %s | %s | %s | %.2f%s | %.2f |" % (
        r["opacity"], r["footprint"], r["spp"], r["rmse"], r["render_s"], t, note,
        t / float(r["render_s"])))
L += ["", "<!-- END GENERATED -->"]
gen = "\n".join(L)
text = open(doc).read() if os.path.exists(doc) else ""
b, e = "<!-- BEGIN GENERATED", "<!-- END GENERATED -->"
if b in text and e in text:
    text = text[:text.index(b)] + gen + text[text.index(e) + len(e):]
else:
    text = text + ("\n" if text else "") + gen + "\n"
open(doc, "w").write(text)
PY
# The figures the page quotes in its prose (scripts/figures.py).
python3 scripts/figures.py fill "$DOC" --qvc-csv "$csv"
echo "quality-vs-cost: wrote $csv, $OUT/quality-vs-cost.png, images, $DOC" >&2
