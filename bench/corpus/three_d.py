"""3D blades: twisted and leaned lofts, a blade on a hub with fillets, CAD as open surfaces
(no solid), a low-aspect-ratio vane (span under the chord)."""
from . import Case
from .profiles import ArcProfile, EnvelopeProfile, circular_camber, smooth_half_thickness

Q5 = (0.0, 0.25, 0.5, 0.75, 1.0)

CASES = [
    Case("twisted_rotor", "3d",
         EnvelopeProfile(circular_camber(35.0), smooth_half_thickness(4.5, 0.3, 0.2),
                         chord=45.0, stagger_deg=-30.0), span=100.0, stations=Q5,
         twist_deg=lambda q: 20.0 * q, errors=("none", "oversize", "twist")),
    Case("leaned_stator", "3d",
         EnvelopeProfile(circular_camber(45.0), smooth_half_thickness(5.0, 0.4, 0.25),
                         chord=45.0, stagger_deg=20.0), span=90.0, stations=Q5,
         lean_mm=lambda q: (4.0 * q, 12.0 * q), errors=("none", "oversize", "twist")),
    Case("hub_fillet", "3d", ArcProfile(), span=70.0, hub=dict(depth=10.0, fillet=2.0),
         errors=("none", "oversize")),
    Case("open_surfaces", "3d",
         EnvelopeProfile(circular_camber(50.0), smooth_half_thickness(5.0, 0.4, 0.3),
                         chord=50.0, stagger_deg=-25.0), span=90.0, mode="surfaces",
         errors=("none", "oversize")),
    Case("low_aspect_vane", "3d",
         EnvelopeProfile(circular_camber(90.0), smooth_half_thickness(10.0, 1.0, 0.4, 0.3),
                         chord=60.0, stagger_deg=-40.0), span=40.0, errors=("none",)),
]
