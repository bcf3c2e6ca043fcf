#!/usr/bin/env bash
# The yardstick (docs/yardstick.md): error against time to image for amalgam's traditional and
# scale-sensitive renderers and Embree, against a converged reference, with the oracle bound
# of level of detail; by default on the field's street and aerial views. Each scene has its own
# section of the page (SECTION below; the commands are in the page).
#
#   scripts/yardstick.sh            full run (about 10-20 minutes on 2 cores; the
#                                   references are cached in build/yardstick/cache, so reruns
#                                   save about a third): writes out/yardstick/*.png and
#                                   *.csv/json and out/yardstick.md (a copy of the docs page
#                                   with its generated part rewritten); touches no docs
#   scripts/yardstick.sh --update-docs   the same into docs/yardstick/ and docs/yardstick.md
#   scripts/yardstick.sh --quick    smoke run (tiny images) into a temporary directory;
#                                   touches nothing under docs/ or out/
#
# Environment: BENCH (default build/bench/amalgam_quality_bench), SCENE (scenes/field.json),
# VIEWS ("aerial street"), THREADS (2), WORK (build/yardstick: results and the reference
# cache), DOCS (out/yardstick; --update-docs: docs/yardstick; with a SECTION,
# yardstick-SECTION instead of yardstick), DOC (out/yardstick.md; --update-docs:
# docs/yardstick.md), SECTION (empty: the page's unnamed generated part, the field's; NAME: the
# part between the markers named NAME, e.g. meadow or soft), BENCH_ARGS (more bench options, e.g.
# "--footprints 1,4 --spps 1,4,16"; the script adds --oracle-box, the box-disc oracle beside
# the K-footprint one), BENCH_ARGS_<view> (options for one view only).
set -euo pipefail
cd "$(dirname "$0")/.."

BENCH=${BENCH:-build/bench/amalgam_quality_bench}
SCENE=${SCENE:-scenes/field.json}
VIEWS=${VIEWS:-"aerial street"}
THREADS=${THREADS:-2}
WORK=${WORK:-build/yardstick}
SECTION=${SECTION:-}
mode=${1:-}
case "$mode" in
  "" | --quick | --update-docs) ;;
  *) echo "usage: scripts/yardstick.sh [--quick | --update-docs]" >&2; exit 2 ;;
esac
# The meadow's and the soft shadows' pages are sections of docs/yardstick.md now: the commands
# that their generated parts quote (DOC=docs/yardstick-meadow.md, DOC=docs/yardstick-soft.md)
# rewrite those sections.
case "${DOC:-}" in
  docs/yardstick-meadow.md | docs/yardstick-soft.md)
    if [[ ! -e "$DOC" && -z "$SECTION" ]]; then
      SECTION=${DOC#docs/yardstick-}
      SECTION=${SECTION%.md}
      echo "yardstick: $DOC is section $SECTION of docs/yardstick.md now; writing there" >&2
      DOC=docs/yardstick.md
    fi ;;
esac
if [[ "$mode" == --update-docs ]]; then
  DOCS=${DOCS:-docs/yardstick${SECTION:+-$SECTION}}
  DOC=${DOC:-docs/yardstick.md}
else
  DOCS=${DOCS:-out/yardstick${SECTION:+-$SECTION}}
  DOC=${DOC:-out/yardstick.md}
  # Outside the docs, the generated part is rewritten in a copy of the page.
  mkdir -p "$(dirname "$DOC")"
  [[ -f "$DOC" || ! -f docs/$(basename "$DOC") ]] || cp "docs/$(basename "$DOC")" "$DOC"
fi
read -r -a extra <<<"${BENCH_ARGS:-}"
extra+=(--oracle-box)
quick=()
if [[ "$mode" == --quick ]]; then
  quick=(--quick)
  WORK=$(mktemp -d)
  DOCS=$WORK/docs
  DOC=$WORK/doc.md
  trap 'rm -rf "$WORK"' EXIT
fi
[[ -x "$BENCH" ]] || { echo "yardstick: $BENCH not found (build first, or set BENCH)" >&2; exit 1; }
/usr/bin/python3 -c "import matplotlib" 2>/dev/null ||
  { echo "yardstick: python3 matplotlib not found (apt-get install python3-matplotlib)" >&2; exit 1; }

dirs=()
command="scripts/yardstick.sh${mode:+ $mode}"
if [[ "$SCENE" != scenes/field.json || -n "$SECTION" ]]; then
  command="SCENE=$SCENE DOC=$DOC${SECTION:+ SECTION=$SECTION} DOCS=$DOCS VIEWS=\"$VIEWS\" $command"
fi
[[ -n "${BENCH_ARGS:-}" ]] && command+=" (BENCH_ARGS=\"$BENCH_ARGS\")"
for view in $VIEWS; do
  echo "yardstick: $view view" >&2
  var="BENCH_ARGS_$view"
  read -r -a view_extra <<<"${!var:-}"
  [[ -n "${!var:-}" ]] && command+=" ($var=\"${!var}\")"
  "$BENCH" --scene "$SCENE" --view "$view" --threads "$THREADS" --out "$WORK/$view" \
    --cache "$WORK/cache" "${quick[@]}" "${extra[@]}" "${view_extra[@]}"
  dirs+=("$WORK/$view")
done

mkdir -p "$DOCS"
for view in $VIEWS; do
  cp "$WORK/$view/results.csv" "$DOCS/$view-results.csv"
  cp "$WORK/$view/results.json" "$DOCS/$view-results.json"
  # The pictures side by side: reference, full detail and scale-sensitive at 16 spp, oracle.
  for img in reference traditional-16spp scale-sensitive-K1-16spp oracle-K1 oracle-K1-box; do
    [[ -f "$WORK/$view/$img.png" ]] && cp "$WORK/$view/$img.png" "$DOCS/$view-$img.png"
  done
done
[[ ${#quick[@]} -gt 0 ]] && command="scripts/yardstick.sh --quick"
commit=$(git rev-parse --short HEAD 2>/dev/null || true)
[[ -n "$commit" ]] && ! git diff --quiet HEAD -- src apps bench 2>/dev/null && commit+=" (with local changes)"
# (A DOC that does not exist yet is created with the section's markers.)
section=()
[[ -n "$SECTION" ]] && section=(--section "$SECTION")
/usr/bin/python3 scripts/yardstick_report.py --doc "$DOC" "${section[@]}" --img "$DOCS" \
  --command "$command" --commit "$commit" "${dirs[@]}"
echo "yardstick: wrote $DOC and $DOCS/" >&2
