"""Turbine sections: high-turning vanes and impulse blades (round edges as unions of circles,
closed forms; elliptic, non-circular noses with the truth computed on the CAD), thick
(t/c >= 25 %) and blunt-TE profiles."""
from . import Case
from .profiles import (ElliptNoseProfile, EnvelopeProfile, circular_camber,
                       smooth_half_thickness)

ALL_ERRORS = ("none", "oversize", "thickness", "le_reshape", "twist")

CASES = [
    Case("vane_110deg", "turbine",
         EnvelopeProfile(circular_camber(110.0), smooth_half_thickness(11.0, 1.2, 0.4, 0.3),
                         chord=50.0, stagger_deg=-35.0), span=90.0, errors=ALL_ERRORS),
    Case("impulse_150deg", "turbine",
         EnvelopeProfile(circular_camber(150.0), smooth_half_thickness(13.0, 0.8, 0.5, 0.5),
                         chord=40.0, stagger_deg=0.0), span=80.0, errors=ALL_ERRORS),
    Case("thick_30pct", "turbine",
         EnvelopeProfile(circular_camber(70.0), smooth_half_thickness(15.0, 2.0, 0.6, 0.35),
                         chord=50.0, stagger_deg=-40.0), span=90.0, errors=ALL_ERRORS),
    Case("blunt_te", "turbine",
         EnvelopeProfile(circular_camber(60.0), smooth_half_thickness(8.0, 1.0, 1.5, 0.35),
                         chord=50.0, stagger_deg=-30.0), span=90.0, errors=ALL_ERRORS),
    Case("vane_ellipse_nose", "turbine-elliptic",
         ElliptNoseProfile(circular_camber(100.0), H=5.0, a=0.25, r_te=0.4, chord=50.0,
                           stagger_deg=-35.0), span=90.0),
    Case("impulse_ellipse_nose", "turbine-elliptic",
         ElliptNoseProfile(circular_camber(130.0), H=6.0, a=0.2, r_te=0.5, chord=45.0),
         span=80.0),
]
