#!/usr/bin/env bash
# Runs a command of this checkout inside a Debian 13 root (FreeCAD 1.0), as a newcomer on
# Debian 13 would: the checkout at /ci/repo and ../shared at /ci/shared, bound in.
#   scripts/test-debian13.sh                 ./run-tests (the README's test command)
#   scripts/test-debian13.sh ./bladeinspect demo --out /tmp/demo-out
# The root is built or checked by scripts/debian13-root.sh (cached in
# /var/cache/bladeinspect/debian13, or $BLADEINSPECT_DEBIAN13_ROOT). FreeCAD and the other
# packages are installed into it by the project's own install step on first use (about 4½ min).
# Needs root.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
shared="$(cd "$here/.." && pwd)/shared"
ROOT="${BLADEINSPECT_DEBIAN13_ROOT:-/var/cache/bladeinspect/debian13}"
[ $# -gt 0 ] || set -- ./run-tests

mkdir -p "$(dirname "$ROOT")"
exec 9>"$ROOT.lock"
flock 9   # one run at a time uses the root
"$here/scripts/debian13-root.sh" "$ROOT" >/dev/null

mounted=()
cleanup() {
  local i
  for (( i = ${#mounted[@]} - 1; i >= 0; i-- )); do
    umount -l "${mounted[$i]}" 2>/dev/null || true
  done
}
trap cleanup EXIT
bind() {  # bind SRC DEST [ro]
  mkdir -p "$2"
  mount --bind "$1" "$2"
  mounted+=("$2")
  [ "${3:-}" != ro ] || mount -o remount,bind,ro "$2"
}
bind /proc "$ROOT/proc"
bind /sys "$ROOT/sys"
bind /dev "$ROOT/dev"
bind /dev/pts "$ROOT/dev/pts"
mkdir -p "$ROOT/dev/shm"
mount -t tmpfs tmpfs "$ROOT/dev/shm" && mounted+=("$ROOT/dev/shm")
bind "$here" "$ROOT/ci/repo"
[ -d "$shared" ] && bind "$shared" "$ROOT/ci/shared" ro
cp -L /etc/resolv.conf "$ROOT/etc/resolv.conf" 2>/dev/null || true

# The session's environment stays outside: the root sees a plain login's.
env -i HOME=/root LANG=C.UTF-8 TERM="${TERM:-dumb}" CI="${CI:-}" \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    chroot "$ROOT" /bin/bash -c 'cd /ci/repo && exec "$@"' bash "$@"
