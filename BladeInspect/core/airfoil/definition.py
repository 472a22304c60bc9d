"""The airfoil definition as one value: every parameter that decides what the kernel's
characteristics mean, and the kernel's version. Its ``digest()`` keys anything stored from a
computed section (nominal cuts, task files), so a changed definition -- or a changed kernel --
can never read back a stale one.

The kernel's fixed numerics (the camber line's contact angle, the end window's skip and
degree, the edge point's window, the max-thickness window, the contour zones' edge fraction)
are not fields: they are covered by ``KERNEL_VERSION``. Bump it whenever one of them, or any
rule of the kernel, changes an answer.
"""

import hashlib
import json
import math
from dataclasses import asdict, dataclass

from ..errors import InputError
from .camber import DEFAULT_METAL_ANGLE_WINDOW_PCT
from .characteristics import DEFAULT_EDGE_OFFSETS_MM
from .chords import CHORD_METHODS
from .edges import DEFAULT_EDGE_ZONE_DEG, LE_RADIUS_SIGMAS

KERNEL_VERSION = 3
# Which end is the LE when neither a point near it nor an upstream direction is given:
# "larger-radius" -- the blunter end, or the end upstream along the engine axis when the two
# radii agree within le_radius_sigmas of their difference; "engine-axis" -- the end upstream
# along the engine axis (the flow runs along +engine axis).
LE_RULES = ("larger-radius", "engine-axis")
_DIGEST_HEX = 16


@dataclass(frozen=True)
class AirfoilDefinition:
    """Every definition parameter of the kernel; the defaults are characteristics()'s."""
    chord_method: str = "nose-tail"
    edge_offsets_mm: tuple = DEFAULT_EDGE_OFFSETS_MM
    edge_zone_deg: float = DEFAULT_EDGE_ZONE_DEG
    metal_angle_window_pct: float = DEFAULT_METAL_ANGLE_WINDOW_PCT
    le_rule: str = "larger-radius"
    le_radius_sigmas: float = LE_RADIUS_SIGMAS
    stations_pct: tuple = ()
    kernel_version: int = KERNEL_VERSION

    def __post_init__(self):
        # Numbers as floats and sequences as tuples: 45 and 45.0 are one definition (one
        # digest, one answer), and the value stays hashable.
        set_ = object.__setattr__
        try:
            for name in ("edge_zone_deg", "metal_angle_window_pct", "le_radius_sigmas"):
                set_(self, name, float(getattr(self, name)))
            for name in ("edge_offsets_mm", "stations_pct"):
                set_(self, name, tuple(float(v) for v in getattr(self, name)))
            set_(self, "kernel_version", int(self.kernel_version))
        except (TypeError, ValueError) as exc:
            raise InputError("airfoil definition: %s" % exc)
        if self.chord_method not in CHORD_METHODS:
            raise InputError("chord method: %r is not one of %s"
                             % (self.chord_method, ", ".join(CHORD_METHODS)))
        if self.le_rule not in LE_RULES:
            raise InputError("LE rule: %r is not one of %s"
                             % (self.le_rule, ", ".join(LE_RULES)))
        numbers = (self.edge_zone_deg, self.metal_angle_window_pct, self.le_radius_sigmas) \
            + self.edge_offsets_mm + self.stations_pct
        if not all(math.isfinite(v) for v in numbers):
            raise InputError("airfoil definition: every number must be finite")

    @classmethod
    def from_dict(cls, data):
        """The definition as_dict() wrote, for this kernel: a stored kernel_version is not
        carried over (what is computed now is this kernel's); unknown fields are an
        InputError."""
        fields = {k: v for k, v in data.items() if k != "kernel_version"}
        unknown = sorted(set(fields) - set(cls.__dataclass_fields__))
        if unknown:
            raise InputError("airfoil definition: unknown field(s) %s" % ", ".join(unknown))
        return cls(**fields)

    def as_dict(self):
        """The fields as JSON-ready data (tuples as lists)."""
        return {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(self).items()}

    def digest(self):
        """A short sha256 of the canonical JSON of the fields (sorted keys, no spaces; floats
        written by repr, as json does): equal definitions give equal digests in every run."""
        text = json.dumps(self.as_dict(), sort_keys=True, separators=(",", ":"),
                          allow_nan=False)
        return hashlib.sha256(text.encode("utf-8")).hexdigest()[:_DIGEST_HEX]
