"""Section table (Table 2), CMM columns and the verdict, against figures computed with numpy
from deviations placed by construction on the demo blade."""
import os
import shutil
import tempfile
import unittest

import numpy as np

from BladeInspect.cad.demo_blade import BladeParams, section_points
from BladeInspect.core.errors import InputError
from BladeInspect.inspection import sections as S
from BladeInspect.inspection import verdict as V
from tests import inspection_fixtures as fx

SPAN = BladeParams().span
# The demo blade's faces interpolate its defining sections at these span fractions exactly, so
# there its leading and trailing edges are known in closed form.
EXACT_FRACTIONS = (0.125, 0.375, 0.625, 0.875)
HEIGHTS = tuple(100.0 * f for f in EXACT_FRACTIONS)


def figures(dev, within=0.02):
    return (len(dev), np.abs(dev).max(), np.sqrt(np.mean(dev ** 2)),
            100.0 * np.mean(np.abs(dev) <= within))


class SectionTableTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = fx.demo_nominal()
        rng = np.random.default_rng(7)
        # Sections at the exact heights plus lines just inside and outside the 0.25 mm band.
        levels = []
        for f in EXACT_FRACTIONS:
            levels += [f * SPAN - 0.4, f * SPAN - 0.2, f * SPAN, f * SPAN + 0.24, f * SPAN + 0.3]
        on_surface, _ = fx.profile_points(cls.nominal, levels)
        cls.known = rng.normal(0.0, 0.012, len(on_surface))
        cls.points = fx.displaced(cls.nominal, on_surface, cls.known)
        cls.result = fx.make_result(cls.nominal, cls.points)
        cls.table = S.section_table(cls.result, cls.nominal, heights_pct=HEIGHTS)

    def test_deviations_are_the_placed_ones_with_sign(self):
        """+ is outside material: the exact distance of a point moved outward is +d."""
        np.testing.assert_allclose(self.result.deviation, self.known, atol=1e-6)

    def test_span_axis_and_planes(self):
        np.testing.assert_allclose(self.table.span_axis, [0, 0, 1], atol=1e-9)
        np.testing.assert_allclose(self.table.span_range, (0.0, SPAN), atol=1e-6)
        for sec, f in zip(self.table.sections, EXACT_FRACTIONS):
            self.assertAlmostEqual(sec.origin[2], f * SPAN, places=6)
            self.assertAlmostEqual(sec.height_pct, 100 * f, places=6)

    def test_figures_match_independent_selection(self):
        z = self.points[:, 2]
        for sec, f in zip(self.table.sections, EXACT_FRACTIONS):
            mine = np.abs(z - f * SPAN) <= 0.25
            n, mx, rms, pct = figures(self.known[mine])
            o = sec.optical
            self.assertEqual(o["n"], n)
            self.assertEqual(sorted(sec.point_index.tolist()), np.flatnonzero(mine).tolist())
            self.assertAlmostEqual(o["max_abs_mm"], mx, delta=1e-6)
            self.assertAlmostEqual(o["rms_mm"], rms, delta=1e-6)
            self.assertAlmostEqual(o["pct_within"], pct, delta=1e-9)

    def test_leading_and_trailing_edges(self):
        """Chord ends at the closed-form nose and tail of the defining section; LE/TE points
        lie within 3 % of the chord of them and carry their own figures."""
        for sec, f in zip(self.table.sections, EXACT_FRACTIONS):
            up, _, _ = section_points(BladeParams(), f)
            le_true, te_true = up[0], up[-1]
            p = sec.profile
            self.assertLess(np.linalg.norm(p.le - le_true), 0.3, "section %s LE" % sec.label)
            self.assertLess(np.linalg.norm(p.te - te_true), 0.6, "section %s TE" % sec.label)
            self.assertAlmostEqual(p.chord, np.linalg.norm(te_true - le_true), delta=0.6)
            pts = self.points[sec.point_index]
            along = (pts - le_true) @ ((te_true - le_true) / np.linalg.norm(te_true - le_true))
            chord = np.linalg.norm(te_true - le_true)
            le = sec.zone == "LE"
            te = sec.zone == "TE"
            self.assertGreater(le.sum(), 3)
            self.assertGreater(te.sum(), 3)
            self.assertTrue(np.all(along[le] < 0.03 * chord + 0.5))
            self.assertTrue(np.all(along[te] > 0.97 * chord - 0.5))
            dev = self.known[sec.point_index]
            self.assertAlmostEqual(sec.optical["le"]["max_abs_mm"], np.abs(dev[le]).max(),
                                   delta=1e-6)
            self.assertAlmostEqual(sec.optical["te"]["rms_mm"],
                                   np.sqrt(np.mean(dev[te] ** 2)), delta=1e-6)

    def test_sides_agree_with_the_faces(self):
        """Between the edges, 'suction'/'pressure' is the role of the face the point lies on."""
        roles = self.nominal.roles
        for sec in self.table.sections:
            face = self.result.face[sec.point_index]
            body = np.isin(sec.zone, ["suction", "pressure"])
            expected = np.where(np.isin(face, roles["suction"]), "suction", "pressure")
            self.assertGreater(body.sum(), 50)
            np.testing.assert_array_equal(sec.zone[body], expected[body])

    def test_json_is_plain(self):
        import json
        doc = json.loads(json.dumps(self.table.to_json()))
        self.assertEqual(len(doc["sections"]), len(HEIGHTS))
        self.assertEqual(doc["sections"][0]["optical"]["n"], self.table.sections[0].optical["n"])
        self.assertIsNone(doc["sections"][0]["cmm"])

    def test_bad_parameters(self):
        with self.assertRaises(InputError):
            S.section_table(self.result, self.nominal, heights_pct=(50, 120))
        with self.assertRaises(InputError):
            S.section_table(self.result, self.nominal, band=0.0)


class SectionColumnTest(unittest.TestCase):
    def test_planes_fitted_from_the_section_column(self):
        """Tilted section planes are recovered from their own points; every point of a section
        belongs to it, whatever its distance from a span height."""
        nominal = fx.demo_nominal()
        tilt = np.radians(4.0)
        normal = np.array([np.sin(tilt), 0.0, np.cos(tilt)])
        on_surface, which = fx.surface_points(nominal, [12.0, 33.0, 55.0], spacing=0.5,
                                              normal=normal)
        rng = np.random.default_rng(11)
        known = rng.normal(0, 0.01, len(on_surface))
        pts = fx.displaced(nominal, on_surface, known)
        labels = np.array([3, 7, 9])[which].astype(float)
        result = fx.make_result(nominal, pts, columns={"section": labels})
        table = S.section_table(result, nominal)
        self.assertEqual([s.label for s in table.sections], ["3", "7", "9"])
        for sec, lab in zip(table.sections, (3, 7, 9)):
            self.assertEqual(sec.source, "section column")
            self.assertLess(np.degrees(np.arccos(min(1.0, sec.normal @ normal))), 0.05)
            mine = labels == lab
            self.assertEqual(sec.optical["n"], int(mine.sum()))
            # figures of the CAD distances of exactly this section's points (at the cut's
            # leading/trailing-edge seam a point moved along one face's normal may be nearer
            # the other face, so the placed value is not always its distance there)
            dev = result.deviation[mine]
            self.assertAlmostEqual(sec.optical["rms_mm"], np.sqrt(np.mean(dev ** 2)), delta=1e-9)
            self.assertAlmostEqual(sec.optical["max_abs_mm"], np.abs(dev).max(), delta=1e-9)
            self.assertGreater(np.mean(np.abs(dev - known[mine]) < 1e-6), 0.98)


class CmmTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = fx.demo_nominal()
        cls.tmp = tempfile.mkdtemp()
        on_surface, which = fx.profile_points(cls.nominal, [0.3 * SPAN, 0.7 * SPAN])
        cls.result = fx.make_result(cls.nominal, on_surface)
        # CMM probing: fewer points, a little off the plane, with known deviations
        rng = np.random.default_rng(5)
        cmm_surface, cmm_which = fx.profile_points(cls.nominal, [0.3 * SPAN + 0.1,
                                                                 0.7 * SPAN - 0.1], n_profile=40)
        cls.cmm_known = rng.normal(0.0, 0.015, len(cmm_surface))
        cls.cmm_pts = fx.displaced(cls.nominal, cmm_surface, cls.cmm_known)
        cls.cmm_which = cmm_which
        cls.path = os.path.join(cls.tmp, "cmm.csv")
        with open(cls.path, "w") as fh:
            fh.write("x,y,z,section\n")
            for k, (p, w) in enumerate(zip(cls.cmm_pts, cmm_which)):
                # every other row names its section, the rest go to the nearest plane
                fh.write("%.9f,%.9f,%.9f,%s\n" % (p[0], p[1], p[2], "" if k % 2 else
                                                  str(w + 1)))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_cmm_columns(self):
        table = S.section_table(self.result, self.nominal, heights_pct=(30, 70), cmm=self.path)
        self.assertEqual(table.cmm_source, self.path)
        for k, sec in enumerate(table.sections):
            mine = self.cmm_which == k
            n, mx, rms, pct = figures(self.cmm_known[mine])
            self.assertEqual(sec.cmm["n"], n)
            self.assertAlmostEqual(sec.cmm["max_abs_mm"], mx, delta=1e-6)
            self.assertAlmostEqual(sec.cmm["rms_mm"], rms, delta=1e-6)
            self.assertAlmostEqual(sec.cmm["pct_within"], pct, delta=1e-9)
            np.testing.assert_allclose(sec.cmm_deviation, self.cmm_known[mine], atol=1e-6)
        self.assertIn("probe", table.to_json()["cmm_note"])

    def test_cmm_errors(self):
        bad = os.path.join(self.tmp, "bad.csv")
        with open(bad, "w") as fh:
            fh.write("x,y,z\n1,2,abc\n")
        with self.assertRaises(InputError) as ctx:
            S.read_cmm(bad)
        self.assertIn("bad.csv", str(ctx.exception))
        with self.assertRaises(InputError):
            S.read_cmm(os.path.join(self.tmp, "missing.csv"))
        unknown = os.path.join(self.tmp, "unknown.csv")
        with open(unknown, "w") as fh:
            fh.write("x,y,z,section\n%f,%f,%f,42\n" % tuple(self.cmm_pts[0]))
        with self.assertRaises(InputError) as ctx:
            S.section_table(self.result, self.nominal, heights_pct=(30, 70), cmm=unknown)
        self.assertIn("42", str(ctx.exception))

    def test_whitespace_cmm(self):
        path = os.path.join(self.tmp, "cmm.txt")
        np.savetxt(path, self.cmm_pts[:20])
        cmm = S.read_cmm(path)
        np.testing.assert_allclose(cmm.xyz, self.cmm_pts[:20])
        self.assertEqual(cmm.section, [None] * 20)


class VerdictTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = fx.demo_nominal()
        levels = np.arange(0.33 * SPAN, 0.67 * SPAN, 0.25)
        cls.on_surface, _ = fx.profile_points(cls.nominal, levels, n_profile=160)
        cls.base = cls.nominal.signed_distance(cls.on_surface)
        cls.noise = np.random.default_rng(2).uniform(-0.006, 0.006, len(cls.on_surface))

    def judge(self, extra):
        pts = fx.displaced(self.nominal, self.on_surface, self.noise + extra)
        result = fx.make_result(self.nominal, pts)
        table = S.section_table(result, self.nominal, heights_pct=(35, 50, 65))
        return result, table, V.judge(result, table, tolerance=0.04)

    def test_clean_blade_passes(self):
        _, _, v = self.judge(0.0)
        self.assertTrue(v["pass"], v["summary"])
        self.assertEqual(v["n_points_out"], 0)
        self.assertTrue(all(s["pass"] for s in v["sections"]))

    def test_defects_found_where_they_were_put(self):
        """Bumps of known height at random places: the worst spot is the bump, with its height,
        its span position, its side (the face it was put on) and the nearest section."""
        rng = np.random.default_rng(21)
        roles = self.nominal.roles
        for trial in range(3):
            body = np.flatnonzero(np.abs(self.base.normal[:, 2]) < 0.5)
            centre_i = rng.choice(body)
            centre = self.on_surface[centre_i]
            chord_pos = centre[0]
            if not -10.0 < chord_pos < 20.0:       # keep it away from the edges
                continue
            height = rng.choice([-1, 1]) * rng.uniform(0.07, 0.12)
            extra = fx.bump(self.on_surface, centre, height, 1.5)
            _, table, v = self.judge(extra)
            self.assertFalse(v["pass"])
            spot = v["worst_spots"][0]
            self.assertAlmostEqual(spot["deviation_mm"], height, delta=0.01)
            self.assertLess(np.linalg.norm(np.array(spot["xyz"]) - centre), 1.0)
            self.assertAlmostEqual(spot["span_pct"], 100 * centre[2] / SPAN, delta=2.0)
            side = "suction" if self.base.face[centre_i] in roles["suction"] else "pressure"
            self.assertEqual(spot["zone"], side)
            nearest = min(table.sections, key=lambda s: abs(s.origin[2] - centre[2]))
            self.assertEqual(spot["section"], nearest.label)
            self.assertIn(side, spot["text"])

    def test_isolated_points_do_not_fail_but_are_counted(self):
        extra = np.zeros(len(self.on_surface))
        extra[[100, 5000]] = [0.2, -0.15]
        _, _, v = self.judge(extra)
        self.assertTrue(v["pass"], v["summary"])
        self.assertEqual(v["n_isolated_out"], 2)
        self.assertEqual(v["n_points_out"], 2)
        self.assertIn("2 isolated", v["summary"])
        result, table, _ = self.judge(extra)
        strict = V.judge(result, table, tolerance=0.04, min_spot_points=1)
        self.assertFalse(strict["pass"])
        self.assertAlmostEqual(strict["worst_spots"][0]["deviation_mm"],
                               0.2 + self.noise[100], delta=1e-6)

    def test_unmeasured_section_is_reported_not_failed(self):
        result, _, _ = self.judge(0.0)
        table = S.section_table(result, self.nominal, heights_pct=(10, 50))
        v = V.judge(result, table, tolerance=0.04)
        self.assertEqual([s["pass"] for s in v["sections"]], [None, True])
        self.assertTrue(v["pass"])
        self.assertIn("1 not measured", v["summary"])

    def test_bad_tolerance(self):
        result, table, _ = self.judge(0.0)
        with self.assertRaises(InputError):
            V.judge(result, table, tolerance=-1)


if __name__ == "__main__":
    unittest.main()
