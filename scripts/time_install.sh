#!/usr/bin/env bash
# Measures the Quick start's package installs on a fresh Debian 12: bootstraps a minimal
# bookworm root in a temporary directory (not timed), points its apt at this machine's mirror,
# copies it, then times `scripts/deps.sh --demo` (what the demo installs: index download,
# packages, unpacking) in one copy and `scripts/deps.sh --test` (what the tests install) in the
# other. Writes "stage<TAB>seconds" lines to FILE, for `scripts/time_tests.sh --install FILE`.
# Needs root and the Debian mirror; installs debootstrap on this machine if it is missing.
# Takes about 5 minutes.
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

base=$(mktemp -d /tmp/amalgam-fresh-root.XXXXXX)
cleanup() {
  for r in "$base/demo" "$base/test"; do umount "$r/proc" 2>/dev/null || true; done
  rm -rf "$base"
}
trap cleanup EXIT

root=$base/demo
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

in_root() {  # ROOT COMMAND
  chroot "$1" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root bash -c "$2"
}
# The bootstrap's package indexes and archives are dropped: each install fetches its own.
in_root "$root" 'apt-get clean; rm -rf /var/lib/apt/lists/*'
cp -a "$root" "$base/test"
timed() {  # NAME ROOT COMMAND: runs COMMAND in ROOT, appends its time to FILE
  local t0 t1
  mount -t proc proc "$2/proc"
  t0=$(date +%s.%N)
  in_root "$2" "$3" >"$2/root/log" 2>&1 || { cat "$2/root/log" >&2; exit 1; }
  t1=$(date +%s.%N)
  umount "$2/proc"
  awk -v n="$1" -v a="$t0" -v b="$t1" 'BEGIN { printf "%s\t%.1f\n", n, b - a }' >>"$out"
}
: >"$out"
timed "scripts/deps.sh --demo (the demo's packages)" "$base/demo" "bash /root/deps.sh --demo"
timed "scripts/deps.sh --test (every package)" "$base/test" "bash /root/deps.sh --test"
cat "$out"
