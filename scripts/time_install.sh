#!/usr/bin/env bash
# Measures the Quick start's package install on a fresh Debian 12: bootstraps a minimal bookworm
# root in a temporary directory (not timed), points its apt at this machine's mirror, then times
# inside it `scripts/deps.sh` (what the demo installs: index download, packages, unpacking) and
# `scripts/deps.sh --test` after it (what the tests add: clang). Writes "stage<TAB>seconds"
# lines to FILE, for `scripts/time_tests.sh --install FILE`. Needs root and the Debian mirror;
# installs debootstrap on this machine if it is missing. Takes about 3-4 minutes.
#
#   scripts/time_install.sh FILE
set -euo pipefail
out=${1:-}
if [ -z "$out" ]; then
  echo "usage: scripts/time_install.sh FILE" >&2
  exit 2
fi
out=$(realpath "$out")
cd "$(dirname "$0")/.."
if [ "$(id -u)" -ne 0 ]; then
  echo "time_install: needs root (debootstrap, chroot)" >&2
  exit 2
fi
if ! command -v debootstrap >/dev/null; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends debootstrap >&2
fi

root=$(mktemp -d /tmp/amalgam-fresh-root.XXXXXX)
cleanup() {
  umount "$root/proc" 2>/dev/null || true
  rm -rf "$root"
}
trap cleanup EXIT

sources=/etc/apt/sources.list.d/debian.sources
mirror=http://deb.debian.org/debian
if [ -f "$sources" ]; then mirror=$(sed -n 's/^URIs: *//p' "$sources" | head -n 1); fi
debootstrap --variant=minbase bookworm "$root" "$mirror" >/dev/null
if [ -f "$sources" ]; then
  rm -f "$root/etc/apt/sources.list"
  cp "$sources" "$root/etc/apt/sources.list.d/"
fi
cp /etc/resolv.conf "$root/etc/resolv.conf"
cp scripts/deps.sh "$root/root/deps.sh"
mount -t proc proc "$root/proc"

in_root() {
  chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root bash -c "$1"
}
timed() {  # NAME COMMAND: runs COMMAND in the root, appends its time to FILE
  local t0 t1
  t0=$(date +%s.%N)
  in_root "$2" >"$root/root/log" 2>&1 || { cat "$root/root/log" >&2; exit 1; }
  t1=$(date +%s.%N)
  awk -v n="$1" -v a="$t0" -v b="$t1" 'BEGIN { printf "%s\t%.1f\n", n, b - a }' >>"$out"
}
# The bootstrap's package indexes and archives are dropped: the install fetches its own.
in_root 'apt-get clean; rm -rf /var/lib/apt/lists/*'
: >"$out"
timed "scripts/deps.sh (the demo's packages)" "bash /root/deps.sh"
timed "scripts/deps.sh --test (adds clang)" "bash /root/deps.sh --test"
cat "$out"
