"""Compressor rotor and stator sections: double circular arc (closed forms of
tests/airfoil_shapes.py), NACA 65 (a = 1.0) mean line, multiple circular arc, C4-like and thin
(t/c 2 %) profiles as unions of circles on their camber lines (every characteristic a closed
form, profiles.EnvelopeProfile)."""
from . import Case
from .profiles import (ArcProfile, EnvelopeProfile, circular_camber, naca65_camber,
                       smooth_half_thickness, two_arc_camber)

ALL_ERRORS = ("none", "oversize", "thickness", "le_reshape", "twist")

CASES = [
    Case("dca_rotor", "compressor", ArcProfile(), span=90.0, errors=ALL_ERRORS),
    Case("dca_stator_staggered", "compressor",
         ArcProfile(Rs=80.0, ys=9.0, Rp=90.0, yp=5.0, x_le=-22.0, x_te=22.0, angle_deg=-30.0),
         span=80.0, errors=ALL_ERRORS),
    Case("dca_thin_2pct", "compressor", ArcProfile(Rs=150.0, ys=1.2, Rp=155.0, yp=0.2),
         span=90.0, errors=ALL_ERRORS),
    Case("naca65_rotor", "compressor",
         EnvelopeProfile(naca65_camber(1.2), smooth_half_thickness(5.0, 0.25, 0.15), chord=50.0,
                         stagger_deg=-35.0), span=90.0, errors=ALL_ERRORS),
    Case("naca65_stator_thick", "compressor",
         EnvelopeProfile(naca65_camber(1.8), smooth_half_thickness(6.5, 0.35, 0.25, x_max=0.45),
                         chord=45.0, stagger_deg=20.0), span=80.0, errors=ALL_ERRORS),
    Case("mca_transonic", "compressor",
         EnvelopeProfile(two_arc_camber(4.0, 14.0, split=0.55),
                         smooth_half_thickness(2.6, 0.12, 0.10, x_max=0.55), chord=55.0,
                         stagger_deg=-50.0), span=90.0, errors=ALL_ERRORS),
    Case("c4like_stator", "compressor",
         EnvelopeProfile(circular_camber(40.0), smooth_half_thickness(5.0, 0.6, 0.3, x_max=0.3),
                         chord=50.0, stagger_deg=15.0), span=80.0, errors=ALL_ERRORS),
    Case("thin_2pct_rotor", "compressor",
         EnvelopeProfile(circular_camber(10.0), smooth_half_thickness(1.0, 0.1, 0.08),
                         chord=50.0, stagger_deg=-55.0), span=90.0, errors=ALL_ERRORS),
]
