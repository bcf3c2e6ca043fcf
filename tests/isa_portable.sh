#!/usr/bin/env bash
# A binary built on an AVX2 machine runs on a CPU without AVX (qemu-user emulating a Nehalem)
# through the portable copy of the hot paths, and writes the same bytes as natively (util/isa.h).
# Also: AMALGAM_SIMD=avx2 on that CPU is a clear error (exit 2); AMALGAM_SIMD=portable natively
# gives the same bytes. Usage: isa_portable.sh AMALGAM_BINARY SOURCE_DIR
set -euo pipefail
bin=$1 src=$2
qemu=$(command -v qemu-x86_64) || { echo "qemu-x86_64 missing (scripts/deps.sh installs qemu-user)"; exit 1; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail=0
run() {  # name, render arguments
  local name=$1; shift
  "$bin" render "$@" --quiet --out "$tmp/$name-native.pfm" --stats "$tmp/$name-native.json"
  AMALGAM_SIMD=portable "$bin" render "$@" --quiet --out "$tmp/$name-portable.pfm"
  "$qemu" -cpu Nehalem "$bin" render "$@" --quiet --out "$tmp/$name-nehalem.pfm" \
    --stats "$tmp/$name-nehalem.json"
  for v in portable nehalem; do
    if cmp -s "$tmp/$name-native.pfm" "$tmp/$name-$v.pfm"; then
      echo "same bytes: $name ($v)"
    else
      echo "DIFFERENT: $name ($v)"; fail=1
    fi
  done
  # The counts agree too: everything but the times, the memory and the command line.
  if python3 - "$tmp/$name-native.json" "$tmp/$name-nehalem.json" <<'PY'
import json, sys
def counts(path):
    j = json.load(open(path))
    for k in ("time_s", "peak_memory_bytes", "command_line"):
        j.pop(k)
    return j
sys.exit(0 if counts(sys.argv[1]) == counts(sys.argv[2]) else 1)
PY
  then
    echo "same stats: $name"
  else
    echo "DIFFERENT stats: $name"; fail=1
  fi
}
run demo builtin:demo --width 48 --height 48 --spp 1 --footprint 2
run wuson /usr/share/assimp/models/PLY/Wuson.ply --width 48 --height 48 --spp 1 --footprint 2
run grid "$src/scenes/wuson-grid.json" --width 48 --height 32 --spp 1
set +e
AMALGAM_SIMD=avx2 "$qemu" -cpu Nehalem "$bin" render builtin:demo --width 8 --height 8 --spp 1 \
  --quiet --out "$tmp/x.pfm" 2>"$tmp/err"
rc=$?
set -e
if [ $rc -eq 2 ] && grep -q "does not support AVX2" "$tmp/err" && [ ! -e "$tmp/x.pfm" ]; then
  echo "AMALGAM_SIMD=avx2 without AVX2: exit 2, $(cat "$tmp/err")"
else
  echo "AMALGAM_SIMD=avx2 without AVX2: expected exit 2 and one line, got $rc: $(cat "$tmp/err")"
  fail=1
fi
exit $fail
