#!/usr/bin/env bash
# Installs this checkout as FreeCAD's BladeInspect workbench: a link from the user Mod folder to
# the repository, the same layout the Addon Manager installs. Run again after moving the checkout.
# The user Mod folder is asked of FreeCAD itself (getUserAppDataDir: ~/.local/share/FreeCAD/Mod
# on 0.20 and 1.0; FreeCAD 1.1 moves it into versioned folders); FREECAD_USER_MOD overrides it.
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
mod_dir="${FREECAD_USER_MOD:-}"
if [ -z "$mod_dir" ]; then
  mod_dir="$("$repo/scripts/fcpython" -c \
    'import os, FreeCAD; print("MODDIR=" + os.path.join(FreeCAD.getUserAppDataDir(), "Mod"))' |
    sed -n 's/^MODDIR=//p')"
  [ -n "$mod_dir" ] || { echo "install-workbench: FreeCAD did not name its user Mod folder" >&2; exit 1; }
fi
target="$mod_dir/BladeInspect"
mkdir -p "$mod_dir"
if [ -e "$target" ] && [ ! -L "$target" ]; then
  echo "install-workbench: $target exists and is not a link; move it away first" >&2
  exit 2
fi
ln -sfn "$repo" "$target"
echo "BladeInspect workbench linked: $target -> $repo (restart FreeCAD)"
