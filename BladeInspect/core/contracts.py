"""The user-facing contracts' defaults, their validation and their JSON form, in one place
(docs/contracts.md): the CLI, the GUI, the pipeline and the document objects read them here."""

import json

import numpy as np

from .errors import InputError

# The profile tolerance +-T (mm) when none is given: the paper's Table 3 bands are +-T,
# +-1.5T and +-2T for this T.
PROFILE_TOLERANCE_MM = 0.04
# Where the profile table's (Table 2) section planes cut the CAD without a section column,
# in % of the span.
SECTION_HEIGHTS_PCT = (10.0, 30.0, 50.0, 70.0, 90.0)
# Built-in parts a command's --cad may name instead of a file (a file of that name wins), with
# cad.demo_blade.make_demo_blade's arguments: the demo blade, and the demo blade on a root
# block whose three datum faces carry the roles datum_primary/secondary/tertiary (for
# --fit datum, which a STEP file's unnamed faces can only reach by index).
BUILTIN_CADS = {"demo": {}, "demo:root-block": {"root_block": True}}


def parse_section_heights(text, name="--section-heights", allow_empty=False):
    """Heights typed as "10,30,50" (commas, semicolons or spaces between them), in % of the
    span, checked as section_heights does."""
    parts = [t for t in str(text).replace(";", ",").replace(" ", ",").split(",") if t]
    try:
        values = [float(t) for t in parts]
    except ValueError:
        raise InputError("%s: %r is not a comma-separated list of numbers"
                         % (name, text)) from None
    return section_heights(values, name, allow_empty)


def section_heights(values, name="--section-heights", allow_empty=False):
    """The section heights as floats; InputError naming ``name`` for a value that is not a
    number or lies outside 0-100 % of the span, or for none at all unless ``allow_empty``."""
    heights = []
    for value in values:
        try:
            height = float(value)
        except (TypeError, ValueError):
            raise InputError("%s: %r is not a number" % (name, value)) from None
        if not (np.isfinite(height) and 0.0 <= height <= 100.0):
            raise InputError("%s: %g is outside 0-100 %% of the span" % (name, height))
        heights.append(height)
    if not heights and not allow_empty:
        raise InputError("%s: at least one height is needed" % name)
    return heights


def profile_tolerance(value, name="--tolerance"):
    """The profile tolerance as a float; InputError unless it is a positive number of mm."""
    try:
        tolerance = float(value)
    except (TypeError, ValueError):
        raise InputError("%s: must be a positive number of mm, got %r" % (name, value)) from None
    if not (np.isfinite(tolerance) and tolerance > 0):
        raise InputError("%s: must be a positive number of mm, got %r" % (name, value))
    return tolerance


def json_default(value):
    """``default=`` for json.dump: numpy arrays and scalars as Python values, objects with a
    ``to_dict()`` (rig kinematics, sensor models) as that dict."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if hasattr(value, "to_dict"):
        return value.to_dict()
    raise TypeError("not JSON serialisable: %r" % type(value))


def json_ready(value):
    """``value`` as plain JSON values (dicts, lists, numbers, strings, None): what reading its
    JSON back gives."""
    return json.loads(json.dumps(value, default=json_default))
