"""Airfoil characteristics of one closed 2D section profile, numpy/scipy only.

Input: the profile in its section plane as an (N, 2) array of points ordered around the loop
(either direction; a repeated closing point is dropped). Unordered measured points are first
ordered by their foot on the nominal (``order_by_nominal``). The profile is represented by a
periodic cubic spline through the points (interpolating; or smoothing with ``noise_mm``, the
points' 1-sigma scatter), parametrised by chord length (about arc length, in mm).

Every definition (mean camber line, chords, edge radii, thicknesses, angles, contour errors)
is written out in docs/user-guide.md; the names here are the fields of result.json's ``airfoil``
block. Lengths in mm, angles in degrees, counter-clockwise positive in the section's 2D frame.

This package's face: the names below are the kernel's public interface; the modules behind
it are its rooms (README.md of core/ lists them). ``AirfoilDefinition`` holds every
definition parameter and the kernel's version, and its ``digest()`` keys stored cuts.
"""

from .camber import DEFAULT_METAL_ANGLE_WINDOW_PCT, END_SKIP, CamberLine
from .characteristics import DEFAULT_EDGE_OFFSETS_MM, Characteristics, characteristics
from .chords import CHORD_METHODS, extent
from .contour import (CONTOUR_EDGE_FRACTION, ZONES, SectionFit, contour, contour_zones,
                      fit_section, lean_bow, order_by_nominal, signed_deviation)
from .definition import KERNEL_VERSION, LE_RULES, AirfoilDefinition
from .edges import (DEFAULT_EDGE_ZONE_DEG, LE_RADIUS_SIGMAS, ZONE_MIN_POINTS, CircleFit2D,
                    circle_radius_factor, edge_points_needed, edge_radius_sigma,
                    edge_spacing_mm, edge_zone_withheld, fit_circle_2d, sparse_edges,
                    withhold_corner_edges, zone_points_enough)
from .medial import MIN_CONTACT_ANGLE_DEG
from .profile import Profile, area_centroid
from .state import characteristics_from_state, characteristics_state

__all__ = [
    "AirfoilDefinition", "CHORD_METHODS", "CONTOUR_EDGE_FRACTION", "CamberLine",
    "Characteristics", "CircleFit2D", "DEFAULT_EDGE_OFFSETS_MM", "DEFAULT_EDGE_ZONE_DEG",
    "DEFAULT_METAL_ANGLE_WINDOW_PCT", "END_SKIP", "KERNEL_VERSION", "LE_RADIUS_SIGMAS",
    "LE_RULES", "MIN_CONTACT_ANGLE_DEG", "Profile", "SectionFit", "ZONES", "ZONE_MIN_POINTS",
    "area_centroid", "characteristics", "characteristics_from_state", "characteristics_state",
    "circle_radius_factor", "contour", "contour_zones", "edge_points_needed",
    "edge_radius_sigma", "edge_spacing_mm", "edge_zone_withheld", "extent", "fit_circle_2d",
    "fit_section", "lean_bow", "order_by_nominal", "signed_deviation", "sparse_edges",
    "withhold_corner_edges", "zone_points_enough",
]
