"""Support for the serial-rig tests: a stand-in for the simulated rig (deterministic per seed
and pass, as the real one promises) and a device-plus-driver pair over a real pty."""
import numpy as np

from BladeInspect.rig.base import AxisLimits, Readings, Rig


class FakeSimulatedRig(Rig):
    """Readings depend on the stage position and a noise stream fixed by (seed, pass_index),
    with some readings missing; enough to tell whether the device measured the same points in
    the same order with the same pass index as the in-process rig."""

    def __init__(self, seed=0, limits=None):
        self.seed = seed
        self.pass_index = 0
        self.limits = limits or AxisLimits()
        self._position = (0.0, 150.0, 100.0, 0.0)
        self._elapsed = 0.0

    def measure(self, stage_xyz, angle_deg, pass_index):
        stage = np.asarray(stage_xyz, float)
        rng = np.random.default_rng((self.seed, pass_index))
        reading = (44.0 + 0.01 * stage[:, 0] - 0.003 * stage[:, 1] + 0.002 * stage[:, 2]
                   + 1e-3 * np.sin(np.radians(angle_deg)) + rng.normal(0.0, 0.002, len(stage)))
        snr = rng.uniform(5.0, 95.0, len(stage))
        missing = rng.random(len(stage)) < 0.1
        reading[missing] = np.nan
        snr[missing] = 0.0
        return reading, snr

    def home(self):
        self._position = (0.0, 150.0, 100.0, 0.0)

    def position(self):
        return self._position

    def move_to(self, x=None, y=None, z=None, a=None):
        self._position = tuple(c if v is None else float(v) for v, c in zip((x, y, z, a), self._position))

    def scan_path(self, path_xyz, angle_deg):
        path = np.asarray(path_xyz, float)
        self.limits.check(path[:, 0], path[:, 1], path[:, 2], angle_deg)
        reading, snr = self.measure(path, angle_deg, self.pass_index)
        self.pass_index += 1
        self._position = tuple(path[-1]) + (float(angle_deg),)
        return Readings(path.copy(), float(angle_deg), reading, snr)

    @property
    def elapsed_s(self):
        return self._elapsed


def section_path(rng, k, y=50.0):
    """A section-like line: X across, Z following a wavy profile, fixed Y."""
    x = np.linspace(-30.0, 30.0, k) + rng.uniform(-0.01, 0.01, k)
    z = 60.0 + 5.0 * np.sin(x / 9.0) + rng.normal(0.0, 1e-4, k)
    return np.column_stack([x, np.full(k, y), z])
