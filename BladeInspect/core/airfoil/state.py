"""A computed section kept as JSON-ready data and read back to the bit."""

import dataclasses
import math

import numpy as np

from ..errors import InputError
from .camber import CamberLine
from .characteristics import Characteristics
from .edges import CircleFit2D

def characteristics_state(ch):
    """A Characteristics as JSON-ready data, its profile left out (the caller keeps the points
    it was made from: characteristics_from_state rebuilds it). Floats are written as Python
    floats, whose JSON text (repr) reads back to the same bits, so a state read back is the
    computed section to the bit (an uncertainty task file keeps its nominal cuts so)."""
    state = {}
    for f in dataclasses.fields(Characteristics):
        if f.name == "profile":
            continue
        state[f.name] = _state_value(getattr(ch, f.name))
    return state


def characteristics_from_state(state, profile):
    """The Characteristics of ``state`` (characteristics_state) on ``profile``: the Profile of
    the points the state was computed from. A state missing a field or holding a value of the
    wrong kind raises InputError."""
    try:
        values = {f.name: _value_of_state(state[f.name])
                  for f in dataclasses.fields(Characteristics) if f.name != "profile"}
        return Characteristics(profile=profile, **values)
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise InputError("airfoil characteristics state: damaged (%s: %s)"
                         % (type(exc).__name__, exc))


def _state_value(v):
    if isinstance(v, np.ndarray):
        if v.dtype.kind == "f" and not np.all(np.isfinite(v)):
            return {"ndarray": [_state_value(x) for x in v.tolist()], "dtype": v.dtype.str}
        return {"ndarray": v.tolist(), "dtype": v.dtype.str}
    if isinstance(v, CircleFit2D):
        return {"circle": {f.name: _state_value(getattr(v, f.name))
                           for f in dataclasses.fields(CircleFit2D)}}
    if isinstance(v, CamberLine):
        return {"camber_line": {name: _state_value(getattr(v, name)) for name in
                                ("le", "centres", "te", "le_tangent", "te_tangent")}}
    if isinstance(v, tuple):
        return {"tuple": [_state_value(x) for x in v]}
    if isinstance(v, list):
        return [_state_value(x) for x in v]
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        # JSON has no NaN or infinity (a thickness station off the profile is NaN)
        return float(v) if math.isfinite(v) else {"float": repr(float(v))}
    if v is None or isinstance(v, str):
        return v
    raise TypeError("no state for a %s" % type(v).__name__)


def _value_of_state(v):
    if isinstance(v, dict):
        if "ndarray" in v:
            return np.array(_value_of_state(v["ndarray"]), dtype=np.dtype(v["dtype"]))
        (kind, body), = v.items()
        if kind == "circle":
            return CircleFit2D(**{k: _value_of_state(x) for k, x in body.items()})
        if kind == "camber_line":
            return CamberLine(**{k: _value_of_state(x) for k, x in body.items()})
        if kind == "tuple":
            return tuple(_value_of_state(x) for x in body)
        if kind == "float":
            return float(body)
        raise ValueError("unknown kind %r" % kind)
    if isinstance(v, list):
        return [_value_of_state(x) for x in v]
    return v
