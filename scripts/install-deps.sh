#!/usr/bin/env bash
# Installs what BladeInspect needs from the distribution's packages, only what is missing.
# Quiet and fast when everything is there already; uses sudo when not root.
set -euo pipefail
PACKAGES=(freecad python3-numpy python3-scipy python3-serial python3-matplotlib xvfb xauth
          poppler-utils python3-distributed)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "bladeinspect: installing ${missing[*]} (distribution packages)" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq >&2
$SUDO apt-get install -y -qq "${missing[@]}" >&2
