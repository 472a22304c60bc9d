"""The rig interface the scan strategy drives, implemented in process by the simulated rig and
over a serial line by the serial driver, so one strategy serves both.

Machine conventions (paper section 4, Fig. 3):
- Three linear stages X, Y, Z carry the sensor; its beam points along -Z of the machine.
  A reading d is the distance along the beam from the sensor's reference to the surface, so a
  measured point in the machine frame is (X, Y, Z - d). The sensor's standoff z_s (44 mm for
  the 50 mm lens) is the centre of its working range z_s +- delta.
- The rotary axis A turns the part about a line parallel to machine +Y (nominally through
  (x, z) = (0, 0); its true position and direction are calibration parameters). The blade's
  span runs along it, so a section line is a scan along X at fixed Y.
- The rotary-table frame is the machine frame turned back by the rotary angle about the axis:
  points from all angles form one rigid set fixed to the part.
"""

from dataclasses import dataclass, field

import numpy as np

from ..core.errors import DeviceError


@dataclass
class AxisLimits:
    """Soft limits of the stages in mm; the rotary axis turns without limit unless given."""
    x: tuple = (-120.0, 120.0)
    y: tuple = (-20.0, 220.0)
    z: tuple = (-40.0, 160.0)
    a: tuple = None

    def check(self, x, y, z, a=None):
        """Raise DeviceError naming the axis when any target lies outside its soft limit."""
        for name, values, (lo, hi) in (("X", x, self.x), ("Y", y, self.y), ("Z", z, self.z)):
            values = np.atleast_1d(values)
            if np.any(values < lo - 1e-9) or np.any(values > hi + 1e-9):
                bad = values[(values < lo - 1e-9) | (values > hi + 1e-9)][0]
                raise DeviceError("soft limit: %s=%.3f mm outside [%.1f, %.1f]" % (name, bad, lo, hi))
        if a is not None and self.a is not None:
            lo, hi = self.a
            if not lo <= a <= hi:
                raise DeviceError("soft limit: A=%.3f deg outside [%.1f, %.1f]" % (a, lo, hi))


@dataclass
class Readings:
    """What one pass along a path returns: one trigger per path point."""
    stage_xyz: np.ndarray          # (K, 3) stage positions at each trigger
    angle_deg: float               # rotary angle held during the pass
    reading_mm: np.ndarray         # (K,) distance along the beam, NaN where there was no reading
    snr: np.ndarray                # (K,) 0..100, 0 where there was no reading
    meta: dict = field(default_factory=dict)


class Rig:
    """Abstract four-axis rig with a point sensor. Every method may raise DeviceError."""

    limits = AxisLimits()
    sensor = None   # a rig.sensor.SensorModel: standoff, range, coverage, rate (what the strategy plans with)

    def home(self):
        raise NotImplementedError

    def position(self):
        """Current (x, y, z, a_deg)."""
        raise NotImplementedError

    def move_to(self, x=None, y=None, z=None, a=None):
        """Rapid move; axes left None stay. Checks soft limits first."""
        raise NotImplementedError

    def scan_path(self, path_xyz, angle_deg):
        """Turn to angle_deg, move through the (K, 3) stage positions in order, take one reading
        at each; return Readings. The whole path is checked against the soft limits first."""
        raise NotImplementedError

    @property
    def elapsed_s(self):
        """Time the real rig would have spent so far (motion and acquisition)."""
        raise NotImplementedError

    def close(self):
        pass
