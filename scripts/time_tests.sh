#!/usr/bin/env bash
# Measures the two Quick start commands as a new user meets them, each on a fresh clone of HEAD
# (scripts/demo.sh; then scripts/test.sh and scripts/test.sh --long, as .ci/run does), and writes
# the figures into README.md and docs/testing.md (scripts/test_times.py). Takes as long as the
# commands do (about 30-40 minutes on 2 cores); run it on an otherwise idle machine.
#
#   scripts/time_tests.sh [--install FILE]   FILE: a fresh root's package install times
#                                            (scripts/time_install.sh), added to the table
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
install=()
if [ "${1:-}" = --install ]; then install=(--install "$(realpath "$2")"); fi
work=$(mktemp -d /tmp/amalgam-times.XXXXXX)
times=$work/times.tsv
now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }

git clone -q "$root" "$work/demo"
t0=$(now)
(cd "$work/demo" && bash scripts/demo.sh) >"$work/demo.log" 2>&1
printf 'demo\t%s\n' "$(since "$t0")" >>"$times"
rm -rf "$work/demo"

git clone -q "$root" "$work/test"
t0=$(now)
(cd "$work/test" && AMALGAM_TEST_TIMES=$times bash scripts/test.sh) >"$work/test.log" 2>&1
printf 'test.sh\t%s\n' "$(since "$t0")" >>"$times"
t0=$(now)
(cd "$work/test" && AMALGAM_TEST_TIMES=$work/long.tsv bash scripts/test.sh --long) \
  >"$work/test-long.log" 2>&1
sed 's/^/long /' "$work/long.tsv" >>"$times"
printf 'test.sh --long\t%s\n' "$(since "$t0")" >>"$times"

/usr/bin/python3 scripts/test_times.py "$times" "$work/test" "${install[@]}"
echo "time_tests: README.md and docs/testing.md updated; logs and trees in $work" >&2
