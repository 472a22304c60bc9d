#!/usr/bin/env bash
# Installs this checkout as FreeCAD's BladeInspect workbench: a link from the user Mod folder to
# the repository, the same layout the Addon Manager installs. Run again after moving the checkout.
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
mod_dir="${FREECAD_USER_MOD:-$HOME/.local/share/FreeCAD/Mod}"
target="$mod_dir/BladeInspect"
mkdir -p "$mod_dir"
if [ -e "$target" ] && [ ! -L "$target" ]; then
  echo "install-workbench: $target exists and is not a link; move it away first" >&2
  exit 2
fi
ln -sfn "$repo" "$target"
echo "BladeInspect workbench linked: $target -> $repo (restart FreeCAD)"
