"""The set-up the CAD airfoil benches share: the section planes at given percentages of a
blade's span (inspection.sections.span_axis_of, through the shape's bounding-box centre), and
the blades they run on (the demo blade, and Rotor 67 when the shared data is there)."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from BladeInspect.inspection.pipeline import load_nominal  # noqa: E402
from BladeInspect.inspection.sections import span_axis_of  # noqa: E402
from tests.helpers import ROTOR67_SECTIONS, have_rotor67  # noqa: E402


def cad_planes(path, heights_pct):
    """(nominal, unit span axis, [(pct, plane origin)]) of the CAD at ``path`` (None: the
    demo blade)."""
    nominal = load_nominal(path)
    span, (lo, hi) = span_axis_of(nominal)
    bb = nominal.shape.BoundBox
    centre = np.array([bb.Center.x, bb.Center.y, bb.Center.z])
    return nominal, span, [(pct, centre + ((lo + pct / 100.0 * (hi - lo)) - centre @ span)
                            * span) for pct in heights_pct]


def each_blade(measure):
    """measure(name, CAD path) for the demo blade and, when present, Rotor 67."""
    measure("demo blade", None)
    if have_rotor67():
        measure("NASA Rotor 67", ROTOR67_SECTIONS)
