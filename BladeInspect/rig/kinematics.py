"""Four-axis kinematics (rig.base conventions): stage positions and readings to machine points,
machine points to the rotary-table frame and back. The rotary axis (a point and a direction)
and an optional linear-stage error model are calibration parameters, stored in RIG.json.

Stage error model: the sensor's true position is M @ commanded with
M = [[1+sx, exy, exz], [0, 1+sy, eyz], [0, 0, 1+sz]] (scale errors s and squareness errors e,
dimensionless/radians): enough to give a calibration test a realistic systematic error.
"""

import json
import os
from dataclasses import dataclass, field

import numpy as np

from ..core import transforms as tf
from ..core.atomic_file import atomic_write
from ..core.errors import InputError

RIG_FILE_KIND = "BladeInspect rig kinematics"


def _vector(value, name, size=3):
    v = np.asarray(value, dtype=float).reshape(-1)
    if v.shape != (size,) or not np.all(np.isfinite(v)):
        raise InputError("rig kinematics %s: expected %d finite numbers, got %r"
                         % (name, size, value))
    return v


@dataclass
class RigKinematics:
    axis_point: np.ndarray = field(default_factory=lambda: np.zeros(3))
    axis_direction: np.ndarray = field(default_factory=lambda: np.array([0.0, 1.0, 0.0]))
    stage_scale: np.ndarray = field(default_factory=lambda: np.zeros(3))         # sx, sy, sz
    stage_squareness: np.ndarray = field(default_factory=lambda: np.zeros(3))    # exy, exz, eyz

    def __post_init__(self):
        self.axis_point = _vector(self.axis_point, "axis_point")
        self.axis_direction = _vector(self.axis_direction, "axis_direction")
        norm = np.linalg.norm(self.axis_direction)
        if norm < 1e-12:
            raise InputError("rig kinematics axis_direction: must not be zero")
        self.axis_direction = self.axis_direction / norm
        self.stage_scale = _vector(self.stage_scale, "stage_scale")
        self.stage_squareness = _vector(self.stage_squareness, "stage_squareness")

    # -- linear stages -----------------------------------------------------------------------

    @property
    def stage_matrix(self):
        sx, sy, sz = self.stage_scale
        exy, exz, eyz = self.stage_squareness
        return np.array([[1 + sx, exy, exz], [0.0, 1 + sy, eyz], [0.0, 0.0, 1 + sz]])

    def sensor_position(self, stage_xyz):
        """Where the sensor's reference really is for commanded stage positions (K,3)."""
        return np.atleast_2d(np.asarray(stage_xyz, dtype=float)) @ self.stage_matrix.T

    def machine_point(self, stage_xyz, reading):
        """Measured points in the machine frame: the sensor's position minus the reading along
        the beam (-Z): (X, Y, Z - d)."""
        p = self.sensor_position(stage_xyz)
        p[:, 2] -= np.asarray(reading, dtype=float)
        return p

    # -- rotary axis -------------------------------------------------------------------------

    def rotation(self, angle_deg):
        """The turn by angle_deg (right-handed about axis_direction) that takes the table frame
        to the machine frame."""
        return tf.rotation_from_vector(self.axis_direction * np.radians(float(angle_deg)))

    def table_to_machine_transform(self, angle_deg):
        R = self.rotation(angle_deg)
        return tf.make_transform(R, self.axis_point - R @ self.axis_point)

    def table_point(self, machine_pts, angle_deg):
        """Machine points turned back by the rotary angle about the axis: the table frame,
        fixed to the part whatever the angle."""
        R = self.rotation(angle_deg)
        return (np.atleast_2d(machine_pts) - self.axis_point) @ R + self.axis_point

    def machine_point_of_table(self, table_pts, angle_deg):
        """Inverse of table_point: where a table-frame point is at this rotary angle."""
        R = self.rotation(angle_deg)
        return (np.atleast_2d(table_pts) - self.axis_point) @ R.T + self.axis_point

    # -- RIG.json ----------------------------------------------------------------------------

    def to_dict(self):
        return {"kind": RIG_FILE_KIND, "version": 1,
                "axis_point": self.axis_point.tolist(),
                "axis_direction": self.axis_direction.tolist(),
                "stage_scale": self.stage_scale.tolist(),
                "stage_squareness": self.stage_squareness.tolist()}

    @classmethod
    def from_dict(cls, data, source="rig kinematics"):
        if not isinstance(data, dict):
            raise InputError("%s: expected a JSON object" % source)
        if data.get("kind", RIG_FILE_KIND) != RIG_FILE_KIND:
            raise InputError("%s: not a rig file (kind %r)" % (source, data.get("kind")))
        known = ("axis_point", "axis_direction", "stage_scale", "stage_squareness")
        try:
            return cls(**{k: data[k] for k in known if k in data})
        except InputError as exc:
            raise InputError("%s: %s" % (source, exc))

    def to_json(self, path, extra=None):
        """Write the rig file ``path`` atomically; ``extra``: more top-level fields (calibrate's
        fit statistics)."""
        with atomic_write(path) as f:
            json.dump(dict(self.to_dict(), **(extra or {})), f, indent=2)
            f.write("\n")

    @classmethod
    def from_json(cls, path):
        return cls.from_dict(read_rig_file(path), source=path)


def read_rig_file(path):
    """The parsed JSON of a RIG.json (calibrate's output); InputError when it is missing or
    not JSON."""
    if not os.path.isfile(path):
        raise InputError("%s: rig file not found" % path)
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as exc:
        raise InputError("%s: not a readable JSON rig file (%s)" % (path, exc))
