"""The airfoil definition as one value (core.airfoil.AirfoilDefinition): frozen, its digest
stable from run to run and changed by every field, its defaults the kernel's own, and
characteristics() given a definition the same to the bit as given the same parameters."""
import dataclasses
import inspect
import json
import os
import subprocess
import sys
import unittest

import numpy as np

from BladeInspect.core import airfoil
from BladeInspect.core.airfoil import AirfoilDefinition
from BladeInspect.core.errors import InputError
from tests.airfoil_shapes import ArcSection

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# The default definition's digest: it keys stored nominal cuts and task files, so it changes
# only with a field or the kernel version (and this line with it).
DEFAULT_DIGEST = "8d5a6278eb94e5ff"
# One changed value per field.
CHANGED = {"chord_method": "caliper", "edge_offsets_mm": (0.5, 1.0, 3.0), "edge_zone_deg": 40.0,
           "metal_angle_window_pct": 40.0, "le_rule": "engine-axis", "le_radius_sigmas": 2.0,
           "stations_pct": (50.0,), "kernel_version": airfoil.KERNEL_VERSION + 1}


class Definition(unittest.TestCase):
    def test_frozen(self):
        d = AirfoilDefinition()
        with self.assertRaises(dataclasses.FrozenInstanceError):
            d.chord_method = "caliper"

    def test_digest_stable_across_runs(self):
        d = AirfoilDefinition()
        self.assertEqual(d.digest(), AirfoilDefinition().digest())
        self.assertEqual(d.digest(), DEFAULT_DIGEST)
        code = ("from BladeInspect.core.airfoil import AirfoilDefinition as D; "
                "print(D().digest(), D(chord_method='tangent', edge_zone_deg=30).digest())")
        # (a fresh plain Python: under FreeCADCmd sys.executable is not one)
        python = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
        out = subprocess.run([python, "-c", code], cwd=ROOT, check=True,
                             capture_output=True, text=True,
                             env=dict(os.environ, PYTHONHASHSEED="123")).stdout.split()
        self.assertEqual(out, [d.digest(),
                               AirfoilDefinition(chord_method="tangent",
                                                 edge_zone_deg=30.0).digest()])

    def test_every_field_changes_the_digest(self):
        names = {f.name for f in dataclasses.fields(AirfoilDefinition)}
        self.assertEqual(names, set(CHANGED))
        seen = {AirfoilDefinition().digest()}
        for name, value in CHANGED.items():
            digest = AirfoilDefinition(**{name: value}).digest()
            self.assertNotIn(digest, seen, name)
            seen.add(digest)

    def test_equal_values_one_digest(self):
        self.assertEqual(AirfoilDefinition(edge_zone_deg=45, edge_offsets_mm=[0.5, 1, 2]),
                         AirfoilDefinition())
        self.assertEqual(AirfoilDefinition(edge_zone_deg=45).digest(), DEFAULT_DIGEST)
        json.dumps(AirfoilDefinition().as_dict())

    def test_defaults_are_the_kernels(self):
        d = AirfoilDefinition()
        kw = {k: p.default for k, p in
              inspect.signature(airfoil.characteristics).parameters.items()}
        self.assertEqual(d.chord_method, kw["chord_method"])
        self.assertEqual(d.edge_offsets_mm, tuple(kw["edge_offsets_mm"]))
        self.assertEqual(d.edge_zone_deg, kw["edge_zone_deg"])
        self.assertEqual(d.metal_angle_window_pct, kw["metal_angle_window_pct"])
        self.assertEqual(d.stations_pct, tuple(kw["stations_pct"]))
        self.assertEqual(d.le_radius_sigmas, airfoil.LE_RADIUS_SIGMAS)
        self.assertEqual(d.le_rule, "larger-radius")
        self.assertEqual(d.kernel_version, airfoil.KERNEL_VERSION)

    def test_read_back(self):
        d = AirfoilDefinition(chord_method="tangent", edge_offsets_mm=(0.3, 1.0),
                              le_rule="engine-axis", metal_angle_window_pct=40.0)
        self.assertEqual(AirfoilDefinition.from_dict(json.loads(json.dumps(d.as_dict()))), d)
        # a stored kernel version is not carried over: the value read is this kernel's
        old = dict(d.as_dict(), kernel_version=d.kernel_version - 1)
        self.assertEqual(AirfoilDefinition.from_dict(old), d)
        with self.assertRaises(InputError):
            AirfoilDefinition.from_dict(dict(d.as_dict(), edge_rule="spline"))

    def test_invalid(self):
        for bad in ({"chord_method": "longest"}, {"le_rule": "upstream"},
                    {"edge_zone_deg": float("nan")}, {"edge_offsets_mm": (1.0, "x")}):
            with self.assertRaises(InputError, msg=str(bad)):
                AirfoilDefinition(**bad)


class WithCharacteristics(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.pts = ArcSection().points(0.05)

    def _same(self, a, b):
        self.assertEqual(json.dumps(airfoil.characteristics_state(a), sort_keys=True),
                         json.dumps(airfoil.characteristics_state(b), sort_keys=True))

    def test_definition_as_the_parameters(self):
        for method in airfoil.CHORD_METHODS:
            with self.subTest(method=method):
                self._same(airfoil.characteristics(
                               self.pts, definition=AirfoilDefinition(chord_method=method)),
                           airfoil.characteristics(self.pts, chord_method=method))
        d = AirfoilDefinition(edge_offsets_mm=(0.3, 1.5), edge_zone_deg=35.0,
                              metal_angle_window_pct=30.0, stations_pct=(25.0, 60.0))
        self._same(airfoil.characteristics(self.pts, definition=d),
                   airfoil.characteristics(self.pts, edge_offsets_mm=(0.3, 1.5),
                                           edge_zone_deg=35.0, metal_angle_window_pct=30.0,
                                           stations_pct=(25.0, 60.0)))

    def test_le_rules(self):
        axis = np.array([1.0, 0.0])
        self._same(airfoil.characteristics(self.pts, definition=AirfoilDefinition(
                       le_rule="engine-axis")),
                   airfoil.characteristics(self.pts, le_upstream=-axis))
        self._same(airfoil.characteristics(self.pts, definition=AirfoilDefinition()),
                   airfoil.characteristics(self.pts))
        # the blunter-end rule's sigmas: this section's radii differ by 16 um, many sigmas at
        # 2 um noise, and the blunter end decides; asked for far more, the engine axis does
        for sigmas, rule in ((3.0, "larger edge radius"),
                             (1e3, "upstream along the engine axis")):
            ch = airfoil.characteristics(self.pts, noise_mm=0.002, definition=AirfoilDefinition(
                le_radius_sigmas=sigmas))
            self.assertEqual(ch.le_rule, rule, sigmas)

    def test_parameter_beside_a_definition(self):
        with self.assertRaises(InputError):
            airfoil.characteristics(self.pts, chord_method="caliper",
                                    definition=AirfoilDefinition())


if __name__ == "__main__":
    unittest.main()
