#!/usr/bin/env bash
# The layering check (scripts/check_layers.py) passes on the source tree, and fails on a copy
# with an upward include and an include cycle (lengths: sizes_test.sh).
set -euo pipefail
src=$1
python3 "$src/scripts/check_layers.py" "$src"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/src/amalgam/math" "$tmp/src/amalgam/render" "$tmp/src/amalgam/scene"
printf '#include "amalgam/render/r.h"\n' > "$tmp/src/amalgam/math/m.h"  # upward
printf '#include "amalgam/math/m.h"\n' > "$tmp/src/amalgam/render/r.h"
printf '#include "amalgam/scene/b.h"\n' > "$tmp/src/amalgam/scene/a.h"  # cycle
printf '#include "amalgam/scene/a.h"\n' > "$tmp/src/amalgam/scene/b.h"
if out=$(python3 "$src/scripts/check_layers.py" "$tmp"); then
  echo "check_layers.py accepted a broken tree:"; echo "$out"; exit 1
fi
for want in "upward" "include cycle"; do
  grep -q "$want" <<<"$out" || { echo "not reported: $want"; echo "$out"; exit 1; }
done
echo "broken tree rejected: $(tail -1 <<<"$out")"
