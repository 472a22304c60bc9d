#!/usr/bin/env bash
# Makes sure a Debian 13 (trixie) root for testing exists and is sound, and prints its path.
#   scripts/debian13-root.sh [ROOT]        default ROOT: /var/cache/bladeinspect/debian13
# The root is a cache kept between runs on one machine, outside any clone. One that is missing,
# half-built (no completion mark) or broken (cannot run its own shell or dpkg) is removed and
# built again from nothing with debootstrap, from the package source this machine's apt uses.
# Needs root (debootstrap, chroot).
set -euo pipefail
ROOT="${1:-/var/cache/bladeinspect/debian13}"
SUITE=trixie
MARK="$ROOT/.bladeinspect-root-complete"

log() { echo "debian13-root: $*" >&2; }

# The Debian archive this machine's apt reads (deb822 .sources or one-line sources.list),
# skipping the security archive: debootstrap takes the suite from the main archive.
apt_mirror() {
  local uri
  uri=$(cat /etc/apt/sources.list.d/*.sources 2>/dev/null |
        awk '/^URIs:/ {for (i = 2; i <= NF; i++) print $i}' | grep -v -- '-security' | head -n 1)
  if [ -z "$uri" ]; then
    uri=$(grep -hE '^\s*deb\s' /etc/apt/sources.list /etc/apt/sources.list.d/*.list 2>/dev/null |
          sed -E 's/^\s*deb\s+(\[[^]]*\]\s+)?//' | awk '{print $1}' | grep -v -- '-security' |
          head -n 1)
  fi
  [ -n "$uri" ] || { log "no Debian package source found in /etc/apt"; exit 1; }
  echo "$uri"
}

# Nothing may stay mounted under the root before it is removed: rm -rf through a bind mount of
# /dev or /proc would reach the host's.
unmount_all() {
  local m
  for m in $(awk -v r="$ROOT" '$2 == r || index($2, r "/") == 1 {print $2}' /proc/mounts |
             sort -r); do
    umount -l "$m" 2>/dev/null || true
  done
  if awk -v r="$ROOT" '$2 == r || index($2, r "/") == 1 {found = 1} END {exit !found}' \
       /proc/mounts; then
    log "cannot unmount everything under $ROOT; not touching it"
    exit 1
  fi
}

sound() {
  [ -f "$MARK" ] || return 1
  chroot "$ROOT" /bin/sh -c 'dpkg --audit >/dev/null && test -x /usr/bin/apt-get' \
    >/dev/null 2>&1 || return 1
}

[ "$(id -u)" -eq 0 ] || { log "needs root (debootstrap and chroot)"; exit 1; }
mkdir -p "$(dirname "$ROOT")"
if sound; then
  echo "$ROOT"
  exit 0
fi

command -v debootstrap >/dev/null || {
  log "installing debootstrap"
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq debootstrap >&2 ||
    { apt-get update -qq >&2 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq debootstrap >&2; }
}
if [ -e "$ROOT" ]; then
  log "rebuilding $ROOT (missing completion mark or broken)"
  unmount_all
  rm -rf --one-file-system "$ROOT"
fi
mirror=$(apt_mirror)
log "debootstrap $SUITE into $ROOT (about a minute)"
start=$(date +%s)
debootstrap --variant=minbase "$SUITE" "$ROOT" "$mirror" >"$ROOT.debootstrap.log" 2>&1 || {
  log "debootstrap failed; its log: $ROOT.debootstrap.log"
  exit 1
}
# The suite's updates carry the point releases' fixes, as on a user's machine.
printf 'deb %s %s main\ndeb %s %s-updates main\n' "$mirror" "$SUITE" "$mirror" "$SUITE" \
  >"$ROOT/etc/apt/sources.list"
touch "$MARK"
log "built in $(( $(date +%s) - start )) s"
echo "$ROOT"
