"""The validation corpus (bench/corpus/) and matrix (bench/validation_matrix.py) hold truths
that are not the airfoil kernel's: checked here against OCC's own exact computations on the
STEP the corpus writes (distance, curvature) and against closed forms, and the matrix run
end to end in its --quick form."""
import contextlib
import io
import json
import os
import shutil
import sys
import tempfile
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "bench"))

import validation_matrix as vm  # noqa: E402
from corpus import all_cases, cad, truth  # noqa: E402
from corpus.profiles import ArcProfile  # noqa: E402


def _case(name):
    return [c for c in all_cases() if c.name == name][0]


def _vertices(xy, z):
    import FreeCAD
    import Part
    return [Part.Vertex(FreeCAD.Vector(float(x), float(y), float(z))) for x, y in xy]


class TestCorpusCAD(unittest.TestCase):
    """The double circular arc's STEP against its closed form, and its oversize part against
    the exact offset, by OCC's distance."""

    @classmethod
    def setUpClass(cls):
        import Part
        cls.tmp = tempfile.mkdtemp(prefix="corpus-test-")
        cls.case = _case("dca_rotor")
        cls.nom_doc = vm.build_part(cls.case, cls.case.profile, "none",
                                    os.path.join(cls.tmp, "nominal.step"))
        cls.big_doc = vm.build_part(cls.case, cls.case.profile, "oversize",
                                    os.path.join(cls.tmp, "oversize.step"))
        cls.nominal = Part.read(os.path.join(cls.tmp, "nominal.step"))
        cls.oversize = Part.read(os.path.join(cls.tmp, "oversize.step"))
        cls.z = cls.case.span / 2

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_step_holds_the_closed_form_profile(self):
        pts = self.case.profile.s.points(spacing=0.05)[::7]
        d = [self.nominal.distToShape(v)[0] for v in _vertices(pts, self.z)]
        # the interpolating B-spline's own error, largest where the edge circle meets an arc
        self.assertLess(np.median(d), 2e-4)
        self.assertLess(max(d), 3e-3)

    def test_edge_radii_are_the_curvature_of_the_cad(self):
        """OCC's curvature of the section's B-spline at the closed-form LE and TE points is
        1/r of the generator's edge circles."""
        import FreeCAD
        s = self.case.profile.s
        curve = cad._curve(cad.select_points(self.case.profile.points()), self.z)
        for point, r in ((s.le_point(), s.r_le), (s.te_point(), s.r_te)):
            u = curve.parameter(FreeCAD.Vector(point[0], point[1], self.z))
            self.assertAlmostEqual(1.0 / curve.curvature(u), r, delta=2e-3 * r)

    def test_oversize_part_is_the_exact_offset(self):
        """Every point of the nominal's profile is OVERSIZE_MM inside the oversize part's
        surface (OCC distance), and its truth grows the edge radii and max thickness by the
        closed forms d and 2d."""
        pts = self.case.profile.s.points(spacing=0.05)[::9]
        import Part
        skin = Part.Compound(self.oversize.Faces)   # a solid's distance is 0 inside it
        d = np.array([skin.distToShape(v)[0] for v in _vertices(pts, self.z)])
        # the interpolating B-splines follow the arcs within 0.2 um and overshoot by up to
        # about 2 um only where an edge circle meets an arc (the curvature jumps 50-fold)
        self.assertLess(np.median(np.abs(d - vm.OVERSIZE_MM)), 2e-4)
        np.testing.assert_allclose(d, vm.OVERSIZE_MM, atol=3e-3)
        dev = vm.true_deviations(self.nom_doc, self.big_doc, "oversize", self.z, 0.5)
        self.assertAlmostEqual(dev["le_radius_mm"], vm.OVERSIZE_MM, places=9)
        self.assertAlmostEqual(dev["max_thickness_mm"], 2 * vm.OVERSIZE_MM, places=9)
        # brute force on the two CAD profiles agrees with the closed forms
        bn, bb = self.nom_doc["stations"][0]["brute"], self.big_doc["stations"][0]["brute"]
        self.assertAlmostEqual(bb["max_thickness_mm"] - bn["max_thickness_mm"],
                               2 * vm.OVERSIZE_MM, delta=2e-5)
        self.assertAlmostEqual(bb["axial_chord_mm"] - bn["axial_chord_mm"],
                               2 * vm.OVERSIZE_MM, delta=2e-5)
        loop = self.case.profile.points()
        steiner = truth.perimeter(loop) * vm.OVERSIZE_MM + np.pi * vm.OVERSIZE_MM ** 2
        self.assertAlmostEqual(bb["area_mm2"] - bn["area_mm2"], steiner, delta=2e-3)


class TestCorpusLofts(unittest.TestCase):
    """A blade through several stations (twisted, leaned, or a twist error on a prism) is the
    station profile turned and shifted at EVERY height, not only at the stations: OCC's own
    slices between them against the corpus's dense profile."""

    def _worst_gap(self, case, error):
        import FreeCAD
        prof = case.profile
        st = vm.stations_of(case, error)
        loops = [(z, truth.rotate(prof.points(), rot) + sh) for q, z, rot, sh in st]
        shape, _ = cad.build(loops, mode=case.mode, hub=case.hub)
        self.assertTrue(shape.isValid(), case.name)
        dist = truth.Distance(prof.points())
        worst = 0.0
        for z in np.linspace(0.03, 0.97, 9) * case.span:
            q = z / case.span
            rot = (case.twist_deg(q) if case.twist_deg else 0.0) + \
                (vm.TWIST_TIP_DEG * q if error == "twist" else 0.0)
            shift = np.asarray(case.lean_mm(q) if case.lean_mm else (0.0, 0.0))
            wires = shape.slice(FreeCAD.Vector(0, 0, 1), float(z))
            self.assertEqual(len(wires), 1, (case.name, z))
            pts = np.array([[p.x, p.y] for e in wires[0].Edges for p in e.discretize(300)])
            worst = max(worst, dist(truth.rotate(pts - shift, -rot)).max())
        return worst

    def test_twist_error_on_a_prism_turns_every_height(self):
        # a loft by Part.makeLoft strayed 2.5 mm from this profile between its stations
        self.assertLess(self._worst_gap(_case("naca65_rotor"), "twist"), 0.005)

    def test_twisted_and_leaned_blades_between_their_stations(self):
        # the skin's pole paths are cubics through rotating poles: 20 deg over 5 stations
        # leaves about 10 um between them, the same in the nominal and the made part
        self.assertLess(self._worst_gap(_case("twisted_rotor"), "none"), 0.012)
        self.assertLess(self._worst_gap(_case("leaned_stator"), "twist"), 0.008)


class TestTwistFitTruth(unittest.TestCase):
    """The twist's truth in the fitted frame (corpus.fit_truth, a linearised least squares
    with the construction's correspondences) against scipy's nonlinear least squares of the
    same points' exact distances to the prismatic nominal."""

    def test_linearised_fit_matches_the_exact_least_squares(self):
        from scipy.optimize import least_squares
        from scipy.spatial.transform import Rotation
        from corpus.fit_truth import fitted_rotation
        case = _case("dca_stator_staggered")
        loop = case.profile.points()
        rng = np.random.default_rng(3)
        n = 3000
        z = rng.uniform(0.0, case.span, n)
        pts2 = loop[rng.integers(0, len(loop), n)]
        tip = 0.3
        rotated = np.array([truth.rotate(p[None], tip * zi / case.span)[0]
                            for p, zi in zip(pts2, z)])
        points = np.column_stack([rotated, z])
        w = rng.uniform(0.5, 1.5, n)
        rel, info = fitted_rotation(case, loop, tip, points, w)
        dist = truth.Distance(loop)

        def residuals(x):
            moved = Rotation.from_rotvec(x[:3]).apply(points) + x[3:]
            return np.sqrt(w) * dist(moved[:, :2])

        # the prism's distance does not see z: delta_z is fixed at 0, as the linear solve
        # leaves it (its column is 0)
        sol = least_squares(lambda x: residuals(np.append(x, 0.0)), np.zeros(5),
                            x_scale=[1e-3, 1e-3, 1e-3, 1e-2, 1e-2], xtol=1e-14, ftol=1e-14)
        omega_z = np.degrees(sol.x[2])
        self.assertAlmostEqual(info["omega_deg"][2], omega_z, delta=2e-4)
        for q in (0.25, 0.5, 0.75):
            self.assertAlmostEqual(rel(q), tip * q + omega_z, delta=2e-4)


class TestCorpusClosedForms(unittest.TestCase):
    def test_unions_of_circles_have_their_construction_as_truth(self):
        """For every union-of-circles case: each circle c(s), r(s) is inside the profile and
        touches it (the camber line is the medial axis, r the inscribed radii), and the largest
        inscribed circle found by brute force is 2 max r."""
        names = ("naca65_rotor", "mca_transonic", "impulse_150deg", "thin_2pct_rotor")
        for case in [_case(n) for n in names]:
            p = case.profile
            loop = p.points()
            dist = truth.Distance(loop)
            k = np.arange(0, len(p.s), 97)
            np.testing.assert_allclose(dist(p.c[k]), p.r[k], atol=2e-4, err_msg=case.name)
            lic, _ = truth.largest_inscribed_circle(loop)
            self.assertAlmostEqual(lic, p.closed_form()["max_thickness_mm"], delta=1e-4,
                                   msg=case.name)

    def test_a_rotated_section_turns_every_angle_and_keeps_every_length(self):
        a, b = ArcProfile(), ArcProfile(angle_deg=7.0)
        ca, cb = a.closed_form(), b.closed_form()
        for k in ca:
            self.assertAlmostEqual(cb[k] - ca[k], 7.0 if k in vm.ANGLES else 0.0, places=9)
        self.assertAlmostEqual(truth.area(b.points()), truth.area(a.points()), places=6)

    def test_at_least_twenty_cases_and_two_public(self):
        cases = all_cases()
        self.assertGreaterEqual(len(cases), 20)
        self.assertGreaterEqual(len([c for c in cases if c.family == "public"]), 2)


class TestJudging(unittest.TestCase):
    def _block(self, dev, u, notes=()):
        return {"airfoil": [{"label": "1", "height_pct": 50.0,
                             "nominal": {"centroid_mm": [0, 0, 45.0], "stagger_deg": 0.0},
                             "deviation": dev, "uncertainty": u, "notes": list(notes)}]}

    def test_statuses(self):
        case = _case("dca_rotor")
        doc = self._block({"chord_mm": 0.001, "le_radius_mm": 0.05, "te_radius_mm": 0.05,
                           "area_mm2": None, "twist_deg": 0.01},
                          {"chord_mm": 0.001, "le_radius_mm": 0.001, "te_radius_mm": 0.001,
                           "area_mm2": None, "twist_deg": 0.004},
                          notes=["TE: 5 points in the TE zone, 12 needed: te radius not "
                                 "measured"])
        rows = {r["key"]: r["status"] for r in vm.judge(case, "none", 20000, doc, None, None)}
        self.assertEqual(rows["chord_mm"], "covered")               # |e| 0.001 <= U 0.002
        self.assertEqual(rows["le_radius_mm"], "CONFIDENT WRONG")   # 0.05 > 2U, no note
        self.assertEqual(rows["te_radius_mm"], "wrong, noted")
        self.assertTrue(vm.flagged(["LE: 4 points in the zone; its edge radius is not "
                                    "measured"], "le_radius_mm"))
        self.assertFalse(vm.flagged(["LE: 4 points in the zone"], "te_radius_mm"))
        self.assertEqual(rows["area_mm2"], "withheld")
        self.assertEqual(rows["twist_deg"], "outside U")            # U < |e| <= 2U


class TestQuickMatrix(unittest.TestCase):
    def test_quick_run_end_to_end(self):
        tmp = tempfile.mkdtemp(prefix="corpus-quick-")
        try:
            out = io.StringIO()
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
                vm.main(["--quick", "--cases", "dca_rotor", "--errors", "oversize",
                         "--cache", tmp, "--json", os.path.join(tmp, "rows.json")])
            text = out.getvalue()
            self.assertIn("Validation matrix", text)
            with open(os.path.join(tmp, "rows.json")) as fh:
                rows = json.load(fh)
            self.assertFalse([r for r in rows if r["status"] == "FAILED"], rows[:1])
            judged = [r for r in rows if "error_value" in r]
            self.assertGreaterEqual(len(judged), 3 * 6)
            # the oversize's max thickness is judged against +2d, not 0
            t = [r["truth"] for r in judged if r["key"] == "max_thickness_mm"]
            np.testing.assert_allclose(t, 2 * vm.OVERSIZE_MM, atol=1e-6)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    unittest.main()
