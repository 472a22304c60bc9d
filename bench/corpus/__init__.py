"""The validation corpus: blade cases by family, each with an independent truth (closed forms
of its construction, or brute force on the exact CAD profile), manufactured errors, CAD built
with FreeCAD and cached as STEP. ``CASES`` lists them; bench/validation_matrix.py runs them.
Nothing here uses BladeInspect's airfoil kernel."""
from dataclasses import dataclass, field


@dataclass
class Case:
    """One blade. ``profile``: the nominal section (profiles.py) in its own frame;
    ``stations``: span fractions of the loft's sections (None: a prismatic extrusion);
    ``twist_deg``/``lean_mm``: the nominal's rotation about the stacking line (z axis) and
    shift at span fraction q (callables); ``hub``: dict(depth, fillet) or None; ``mode``:
    "solid" or "surfaces"; ``errors``: the manufactured errors that apply; ``cad_path``: a
    public CAD file used as it is (no build)."""
    name: str
    family: str
    profile: object = None
    span: float = 80.0
    stations: tuple = None
    twist_deg: object = None
    lean_mm: object = None
    hub: dict = None
    mode: str = "solid"
    errors: tuple = ("none", "oversize", "twist")
    cad_path: str = None
    source: str = "generated"
    extra: dict = field(default_factory=dict)


def all_cases():
    from . import compressor, turbine, three_d, public
    cases = compressor.CASES + turbine.CASES + three_d.CASES + public.cases()
    names = [c.name for c in cases]
    assert len(names) == len(set(names)), "case names must be unique"
    return cases
