"""The four-axis rig simulated in process: a part at a known pose on the rotary table, exact rays
down the sensor's beam onto its CAD, the sensor model on top (rig.sensor), simulated time.

The serial pseudo-terminal device wraps this class and calls the same ``measure``; since the
noise stream of a pass depends only on (seed, pass_index), both give identical points.
"""

import numpy as np
from scipy.spatial import cKDTree

from ..core import transforms as tf
from ..core.errors import DeviceError, InputError
from .base import AxisLimits, Readings, Rig
from .kinematics import RigKinematics
from .sensor import SensorModel

BEAM_MACHINE = np.array([0.0, 0.0, -1.0])
# Part centre on the table: along the axis far enough from the Y stage's ends that a 70 mm
# span fits between the soft limits with room to probe past its ends.
DEFAULT_TABLE_Y = 60.0


def random_fixture_pose(rng, blade_span_axis=(0.0, 0.0, 1.0), cad_center=(0.0, 0.0, 0.0),
                        table_y=DEFAULT_TABLE_Y, max_tilt_deg=5.0, max_offset_mm=10.0):
    """A random way to clamp a blade on the rotary table -> table_to_cad (4x4).

    The blade's span (``blade_span_axis`` in CAD) runs along the rotary axis (+Y of the table),
    turned by any angle about it, tilted off it by up to ``max_tilt_deg`` and its CAD point
    ``cad_center`` put off the axis by up to ``max_offset_mm``, at ``table_y`` along it."""
    span = np.asarray(blade_span_axis, dtype=float)
    span = span / np.linalg.norm(span)
    y = np.array([0.0, 1.0, 0.0])
    cross = np.cross(span, y)
    if np.linalg.norm(cross) < 1e-12:
        align = np.eye(3) if span @ y > 0 else np.diag([1.0, -1.0, -1.0])
    else:
        angle = np.arctan2(np.linalg.norm(cross), span @ y)
        align = tf.rotation_from_vector(cross / np.linalg.norm(cross) * angle)
    spin = tf.rotation_from_vector(y * rng.uniform(0.0, 2.0 * np.pi))
    tilt_dir = rng.uniform(0.0, 2.0 * np.pi)
    tilt_axis = np.array([np.cos(tilt_dir), 0.0, np.sin(tilt_dir)])
    tilt = tf.rotation_from_vector(tilt_axis * np.radians(rng.uniform(0.0, max_tilt_deg)))
    R = tilt @ spin @ align
    off_angle = rng.uniform(0.0, 2.0 * np.pi)
    off = max_offset_mm * np.sqrt(rng.uniform())
    target = np.array([off * np.cos(off_angle), table_y, off * np.sin(off_angle)])
    table_from_cad = tf.make_transform(R, target - R @ np.asarray(cad_center, dtype=float))
    return tf.invert_transform(table_from_cad)


def _smooth_profile(r, radius):
    """(1 - (r/R)^2)^3 inside R, 0 outside: twice differentiable, exactly zero beyond R."""
    q = np.clip(1.0 - (r / radius) ** 2, 0.0, None)
    return q * q * q


def make_bump(center, radius, height):
    """A smooth bump of ``height`` mm (+ adds material) on the surface within ``radius`` of
    ``center`` (CAD frame): an error_field for SimulatedRig."""
    c = np.asarray(center, dtype=float)
    if not radius > 0:
        raise InputError("make_bump: radius must be positive, got %r" % (radius,))

    def field(points):
        return height * _smooth_profile(np.linalg.norm(np.asarray(points) - c, axis=1), radius)
    return field


def make_thickening(curve_points, radius, height):
    """Material added (``height`` mm at the curve, fading to 0 at ``radius``) near a curve given
    as dense CAD points, e.g. a leading edge left thick by polishing: an error_field."""
    pts = np.asarray(curve_points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) == 0:
        raise InputError("make_thickening: curve_points must be (M, 3)")
    if not radius > 0:
        raise InputError("make_thickening: radius must be positive, got %r" % (radius,))
    tree = cKDTree(pts)

    def field(points):
        r, _ = tree.query(np.asarray(points, dtype=float), distance_upper_bound=radius)
        return height * _smooth_profile(np.where(np.isfinite(r), r, radius), radius)
    return field


def random_fixture_pose_of(part, rng, span_axis=None):
    """random_fixture_pose of ``part`` (with ``bbox_corners``): its span along the rotary axis
    (``span_axis``, default the bounding box's longest side), the box centre near the axis."""
    corners = np.asarray(part.bbox_corners, dtype=float)
    if span_axis is None:
        span_axis = np.eye(3)[int(np.argmax(corners.max(axis=0) - corners.min(axis=0)))]
    return random_fixture_pose(rng, blade_span_axis=span_axis,
                               cad_center=0.5 * (corners.min(axis=0) + corners.max(axis=0)))


def simulated_rig_for(part, seed=0, **rig_options):
    """A SimulatedRig of ``part`` clamped at a random fixture pose drawn from ``seed``
    (random_fixture_pose_of). The same seed gives the same pose and the same readings."""
    pose = random_fixture_pose_of(part, np.random.default_rng(seed))
    return SimulatedRig(part, pose, seed=seed, **rig_options)


class SimulatedRig(Rig):
    """``part``: anything with raycast(origins, directions) -> (t, face, normal) in the CAD
    frame, normals outward (cad.nominal.Nominal, calibration.SpherePart, analytic test parts).
    ``table_to_cad``: the part's pose on the table (maps table-frame points into the CAD frame).
    ``kinematics``: the rig's TRUE geometry (axis, stage errors); a strategy may believe another.
    ``error_field(cad_points) -> mm``: the manufactured part's deviation along the outward
    normal (+ adds material)."""

    def __init__(self, part, table_to_cad, sensor=None, kinematics=None, seed=0,
                 error_field=None, limits=None, feed_mm_s=20.0, rapid_mm_s=50.0,
                 rotary_deg_s=30.0):
        T = np.asarray(table_to_cad, dtype=float)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)):
            raise InputError("table_to_cad: expected a finite 4x4 matrix")
        for name, value in (("feed_mm_s", feed_mm_s), ("rapid_mm_s", rapid_mm_s),
                            ("rotary_deg_s", rotary_deg_s)):
            if not value > 0:
                raise InputError("simulated rig %s: must be positive, got %r" % (name, value))
        self.part = part
        self.table_to_cad = T
        self.sensor = sensor if sensor is not None else SensorModel()
        self.kinematics = kinematics if kinematics is not None else RigKinematics()
        self.seed = int(seed)
        self.error_field = error_field
        self.limits = limits if limits is not None else AxisLimits()
        self.feed_mm_s = float(feed_mm_s)
        self.rapid_mm_s = float(rapid_mm_s)
        self.rotary_deg_s = float(rotary_deg_s)
        self.pass_index = 0
        self._position = np.array([0.0, 0.0, self.limits.z[1], 0.0])
        self._elapsed = 0.0

    # -- the physics -------------------------------------------------------------------------

    def cad_from_machine(self, angle_deg):
        """4x4 taking machine points at this rotary angle into the CAD frame (the truth)."""
        machine_to_table = tf.invert_transform(
            self.kinematics.table_to_machine_transform(angle_deg))
        return self.table_to_cad @ machine_to_table

    def measure(self, stage_xyz, angle_deg, pass_index):
        """Readings at the given stage positions and rotary angle -> (reading (K,), snr (K,)).
        Depends only on the inputs, the seed and pass_index (not on the rig's state)."""
        stage = np.atleast_2d(np.asarray(stage_xyz, dtype=float))
        T = self.cad_from_machine(angle_deg)
        origins = tf.apply_transform(T, self.kinematics.sensor_position(stage))
        beam = T[:3, :3] @ BEAM_MACHINE
        t, _, normal = self.part.raycast(origins, np.tile(beam, (len(stage), 1)))
        t = np.asarray(t, dtype=float)
        cos_inc = -(np.asarray(normal, dtype=float) @ beam)
        hit = np.isfinite(t) & (cos_inc > 0)
        t = np.where(hit, t, np.nan)
        if self.error_field is not None and np.any(hit):
            # First order in the offset h: the surface moved by h along the normal is met
            # h / cos(incidence) earlier along the beam.
            spots = origins[hit] + t[hit, None] * beam
            t[hit] -= np.asarray(self.error_field(spots), dtype=float) / cos_inc[hit]
        incidence = np.where(hit, np.arccos(np.clip(cos_inc, -1.0, 1.0)), np.pi)
        rng = np.random.default_rng([self.seed, int(pass_index)])
        return self.sensor.read(t, incidence, rng)

    # -- the Rig interface -------------------------------------------------------------------

    def home(self):
        self.move_to(x=0.0, y=float(np.clip(0.0, *self.limits.y)), z=self.limits.z[1], a=0.0)

    def position(self):
        return tuple(float(v) for v in self._position)

    def move_to(self, x=None, y=None, z=None, a=None):
        target = np.array([c if v is None else float(v)
                           for v, c in zip((x, y, z, a), self._position)])
        self.limits.check(target[0], target[1], target[2], target[3])
        self._travel(target, self.rapid_mm_s)

    def set_pass_index(self, index):
        """Which noise stream the next pass uses: a resumed scan continues where it stopped."""
        self.pass_index = int(index)

    def scan_path(self, path_xyz, angle_deg):
        path = np.atleast_2d(np.asarray(path_xyz, dtype=float))
        if path.ndim != 2 or path.shape[1] != 3 or len(path) == 0 or not np.all(np.isfinite(path)):
            raise DeviceError("scan path: expected finite (K, 3) stage positions")
        angle = float(angle_deg)
        self.limits.check(path[:, 0], path[:, 1], path[:, 2], angle)
        start = self._elapsed
        self._travel(np.append(path[0], angle), self.rapid_mm_s)
        length = float(np.sum(np.linalg.norm(np.diff(path, axis=0), axis=1)))
        # The stages move at the feed, but never faster than the sensor can trigger.
        self._elapsed += max(length / self.feed_mm_s, len(path) / self.sensor.rate_hz)
        self._position = np.append(path[-1], angle)
        index = self.pass_index
        reading, snr = self.measure(path, angle, index)
        self.pass_index += 1
        return Readings(path.copy(), angle, reading, snr,
                        meta={"pass_index": index, "simulated_s": self._elapsed - start})

    @property
    def elapsed_s(self):
        return self._elapsed

    def _travel(self, target, speed):
        linear = np.linalg.norm(target[:3] - self._position[:3]) / speed
        rotary = abs(target[3] - self._position[3]) / self.rotary_deg_s
        # The axes move together: the slower one sets the time.
        self._elapsed += max(linear, rotary)
        self._position = np.asarray(target, dtype=float)
