"""The nominal cuts kept in an uncertainty task file (inspection/airfoil_task.py,
core.airfoil.characteristics_state): a later blade of the task reads the nominal
characteristics back instead of computing them, and gets every value, nominal and measured,
to the bit of a run that computed them; a kept cut is used only for the very points and
arguments it was computed from; a file whose kept cuts were changed is refused.

The truth is a fresh computation of the same cut in a process that has remembered nothing
(inspection.airfoil_stage.clear_nominal_cache) and a JSON round trip through text, on shapes with
the awkward values a state must carry: a corner edge's withheld radius (None), a thickness
station off the profile (NaN), a profile's tuples and circles."""
import dataclasses
import json
import os
import shutil
import tempfile
import unittest
from unittest import mock

import numpy as np

from BladeInspect.core import airfoil as kernel
from BladeInspect.core.errors import InputError
from BladeInspect.inspection import airfoil_stage as stage_mod
from BladeInspect.inspection import airfoil_task as task_u
from tests.airfoil_shapes import ArcSection, NacaSection
from tests.helpers import demo_nominal
from tests.test_airfoil_task_u import _measurement, _readings, _run


def _same(a, b):
    """Every field of two Characteristics equal to the bit (NaN equal to NaN); the camber
    line and the profile compared by what they give."""
    for f in dataclasses.fields(kernel.Characteristics):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if f.name == "profile":
            u = np.linspace(0.0, x.length, 997, endpoint=False)
            np.testing.assert_array_equal(x.eval(u), y.eval(u))
        elif f.name == "mcl":
            s = np.linspace(0.0, x.length, 501)
            for p, q in zip(x.at(s), y.at(s)):
                np.testing.assert_array_equal(p, q)
            np.testing.assert_array_equal(x.te_tangent, y.te_tangent)
        elif isinstance(x, kernel.CircleFit2D):
            np.testing.assert_array_equal(x.center, y.center)
            assert (x.radius, x.rms, x.n_points, x.zone_deg) == \
                (y.radius, y.rms, y.n_points, y.zone_deg), f.name
        elif isinstance(x, np.ndarray):
            assert x.dtype == y.dtype, f.name
            np.testing.assert_array_equal(x, y, err_msg=f.name)
        elif isinstance(x, (list, tuple)) and not all(isinstance(v, str) for v in x):
            np.testing.assert_array_equal(np.asarray(x, dtype=float),
                                          np.asarray(y, dtype=float), err_msg=f.name)
            assert type(x) is type(y), f.name
        else:
            assert x == y, (f.name, x, y)


class StateRoundTrip(unittest.TestCase):
    def _round_trip(self, pts, **kw):
        fresh = kernel.characteristics(pts, **kw)
        text = json.dumps(kernel.characteristics_state(fresh), allow_nan=False)
        back = kernel.characteristics_from_state(json.loads(text), kernel.Profile(pts))
        _same(fresh, back)
        return fresh, back

    def test_arc_section(self):
        self._round_trip(ArcSection(angle_deg=17.0, shift=(3.0, -2.0)).points(0.05))

    def test_corner_edge_and_station_off_the_profile(self):
        sec = NacaSection("2412", c=50.0)
        xi = np.linspace(0.0, 1.0, 1500)
        upper, lower = sec.surface(xi, True), sec.surface(xi, False)
        upper[-1] = lower[-1] = 0.5 * (upper[-1] + lower[-1])
        pts = np.vstack([lower, upper[::-1][1:-1]])
        fresh, back = self._round_trip(pts, stations_pct=(10.0, 50.0, 100.0))
        self.assertIsNone(back.te_radius_mm)                  # a corner's, withheld
        self.assertTrue(np.isnan(back.thickness_mm[-1]))     # the station at the TE point

    def test_a_damaged_state_is_an_input_error(self):
        pts = ArcSection().points(0.05)
        state = kernel.characteristics_state(kernel.characteristics(pts))
        del state["le_circle"]
        with self.assertRaises(InputError):
            kernel.characteristics_from_state(state, kernel.Profile(pts))


class TaskKeepsTheNominal(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = demo_nominal()
        sections = _readings(cls.nominal)
        cls.tmp = tempfile.mkdtemp(prefix="task_nominal_")
        cls.path = os.path.join(cls.tmp, "task.json")
        cls.blade_a = _measurement(cls.nominal, sections, 0.002, 1)
        cls.blade_b = _measurement(cls.nominal, sections, 0.002, 3)
        stage_mod.clear_nominal_cache()
        _run(cls.nominal, cls.blade_a, stage_mod.Options(task_uncertainty=cls.path,
                                                         task_draws=2))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)
        stage_mod.clear_nominal_cache()

    def _stage(self, path, kernel_runs=None):
        """Blade b's stage in a process that remembers no nominal cut."""
        stage_mod.clear_nominal_cache()
        real = kernel.characteristics
        runs = []

        def counting(*a, **k):
            runs.append(k.get("noise_mm", 0.0))
            return real(*a, **k)
        with mock.patch.object(kernel, "characteristics", counting):
            stage, _ = _run(self.nominal, self.blade_b,
                            stage_mod.Options(task_uncertainty=path))
        if kernel_runs is not None:
            kernel_runs.extend(runs)
        return stage

    def test_second_blade_reads_the_nominal_back_to_the_bit(self):
        runs = []
        kept = self._stage(self.path, runs)
        # only the two measured sections are computed (noisy points), no nominal cut
        self.assertEqual(len(runs), 2)
        self.assertTrue(all(n > 0 for n in runs), runs)
        # a file without the kept cuts (as made before they were kept): all computed
        doc = json.load(open(self.path))
        self.assertEqual(len(doc["nominal"]), 2)
        doc.pop("nominal"), doc.pop("nominal_digest")
        bare = os.path.join(self.tmp, "bare.json")
        json.dump(doc, open(bare, "w"))
        runs = []
        computed = self._stage(bare, runs)
        self.assertEqual(len(runs), 4)
        for a, b in zip(kept.blocks, computed.blocks):
            for part in ("nominal", "measured", "deviation", "uncertainty"):
                self.assertEqual(json.dumps(a[part], sort_keys=True),
                                 json.dumps(b[part], sort_keys=True), part)
        for a, b in zip(kept.sections, computed.sections):
            _same(a.nominal, b.nominal)

    def test_a_cut_of_other_points_is_computed(self):
        doc = json.load(open(self.path))
        task = task_u.load(self.path)
        states = dict(task.nominal)
        xy = ArcSection().points(0.05)
        ch = stage_mod.nominal_characteristics(xy, kernel.AirfoilDefinition(), None, None,
                                               states)
        self.assertEqual(len(states), len(doc["nominal"]) + 1)   # a new key, none reused
        _same(ch, kernel.characteristics(xy, edge_offsets_mm=(0.5, 1.0, 2.0)))

    def test_a_kept_cut_of_another_version_is_computed(self):
        """A kept state that no longer fits Characteristics (a field it lacks, as a file made
        by an older version would) is computed afresh and kept anew, not a section lost."""
        xy = ArcSection().points(0.05)
        args = (kernel.AirfoilDefinition(), None, None)
        states = {}
        stage_mod.clear_nominal_cache()
        stage_mod.nominal_characteristics(xy, *args, states)
        (key, state), = states.items()
        del state["le_circle"]
        stage_mod.clear_nominal_cache()
        ch = stage_mod.nominal_characteristics(xy, *args, states)
        _same(ch, kernel.characteristics(xy, edge_offsets_mm=(0.5, 1.0, 2.0)))
        self.assertIn("le_circle", states[key])

    def test_changed_nominal_cut_refused(self):
        doc = json.load(open(self.path))
        key = sorted(doc["nominal"])[0]
        doc["nominal"][key]["max_thickness_mm"] += 1e-6
        path = os.path.join(self.tmp, "edited.json")
        json.dump(doc, open(path, "w"))
        with self.assertRaises(InputError) as ctx:
            task_u.load(path)
        self.assertIn("nominal_digest", str(ctx.exception))


if __name__ == "__main__":
    unittest.main()
