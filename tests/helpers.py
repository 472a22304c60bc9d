"""Shared test helpers: paths to the shared real-blade data, temporary folders."""
import os

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.normpath(os.path.join(REPO, "..", "shared"))
ROTOR67_DIR = os.path.join(SHARED, "data", "blades", "nasa_rotor67")
ROTOR67_SECTIONS = os.path.join(ROTOR67_DIR, "rotor67geometry.dat")
ROTOR67_CLOUD = os.path.join(ROTOR67_DIR, "MoveSurface_NASA_R67_parablade.txt")


def have_rotor67():
    return os.path.exists(ROTOR67_SECTIONS)
