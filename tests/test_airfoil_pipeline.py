"""The airfoil characteristics stage (inspection/airfoil_stage.py, issue 15) on the demo blade, against
truths made independently of the kernel: readings simulated on the CAD's own section points
(OCC's cut, exact on the CAD and the plane), a part made as the CAD offset outward, one section
turned or shifted by a known amount, and OCC's centre of mass of a section face."""
import csv
import html
import json
import os
import shutil
import tempfile
import unittest

import numpy as np

from BladeInspect.core import stats
from BladeInspect.core import transforms as tf
from BladeInspect.inspection import airfoil_stage as stage_mod
from BladeInspect.inspection import airfoil_values as values
from BladeInspect.inspection import sections as sections_mod
from BladeInspect.inspection.result import RegistrationResult
from BladeInspect.measurement.planning import nominal_section
from BladeInspect.inspection.run_options import RunOptions
from tests.helpers import demo_nominal

HEIGHTS = (30.0, 50.0, 70.0)
# mm between the simulated readings along a section: the CAD cut's own spacing, which the
# kernel's figures are for (the planned scan's default 0.1 mm leaves an edge of 0.14 mm radius
# a handful of points: issue 15 item 7, not done here).
SPACING = 0.02
COARSE_SPACING = 0.05    # for the tolerance and report wiring
SENSOR_SIGMA = 0.002     # the sensor's 1 sigma noise (mm) for the perfect part
QUIET_SIGMA = 0.0005     # for the known changes: the change, not the noise, is read back
# What the kernel reaches on one scan's noisy points (docs/validation.md, "The kernel on
# exact and noisy sections"); 2 um / 0.005 deg are not met. Largest |measured - nominal| over 3
# seeds x 3 sections (sigma 2 um, 0.02 mm): nose-tail chord 3.2 um, stagger 0.0085 deg, LE
# radius 7.9 um, TE radius 5.5 um, inlet angle 0.88 deg, outlet angle 1.9 deg, thickness
# 0.5 mm from an edge 3.7 um, max-thickness position 0.48 %.
KERNEL_LIMITS = {"chord_mm": 0.006, "stagger_deg": 0.015, "le_radius_mm": 0.012,
                 "te_radius_mm": 0.012, "inlet_angle_deg": 2.0, "outlet_angle_deg": 3.0,
                 "max_thickness_pos_pct": 1.0, "le_thickness_mm[0]": 0.006,
                 "te_thickness_mm[0]": 0.006}


def _result(nominal, xyz):
    """A registration result of points already in the CAD frame (identity pose), with the
    pose covariance of a well-measured blade (1 um, 1 urad)."""
    d = nominal.signed_distance(xyz)
    return RegistrationResult(
        measured_to_cad=np.eye(4), points_cad=xyz, deviation=d.distance,
        inlier=np.ones(len(xyz), bool), closest=d.closest, normal=d.normal, face=d.face,
        snr=None, columns={}, n_rows_skipped=0, rms_mm=float(np.std(d.distance)),
        pose_covariance=np.diag([1e-6] * 3 + [1e-12] * 3), center=xyz.mean(axis=0),
        pose_uncertainty_mm=1e-3, deviation_stats=stats.deviation_statistics(d.distance),
        coarse={})


class Readings:
    """The CAD's section points at HEIGHTS, each with its outward normal."""
    cache = {}

    @classmethod
    def get(cls, nominal, spacing=SPACING):
        if spacing not in cls.cache:
            planes = stage_mod.nominal_planes(nominal, HEIGHTS)
            cls.cache[spacing] = {
                "planes": planes,
                "sections": [nominal_section(nominal, p.origin, p.normal, spacing)[:2]
                             for p in planes]}
        return cls.cache[spacing]


def _stage(nominal, sections_xyz, opts=None):
    xyz = np.vstack(sections_xyz)
    result = _result(nominal, xyz)
    table = sections_mod.section_table(result, nominal, heights_pct=HEIGHTS, band=0.01)
    opts = opts or stage_mod.Options(draws=0)
    return stage_mod.run_stage(nominal, stage_mod.planes_of_table(table), opts, result,
                               table.span_axis), table, result


def _noisy(sections, sigma, seed, move=None):
    rng = np.random.default_rng(seed)
    out = []
    for k, (p, n) in enumerate(sections):
        q = p + n * (sigma * rng.standard_normal(len(p)))[:, None]
        out.append(move(k, q, n) if move else q)
    return out


class PerfectPart(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = demo_nominal()
        cls.readings = Readings.get(cls.nominal)
        cls.stage, cls.table, cls.result = _stage(
            cls.nominal, _noisy(cls.readings["sections"], SENSOR_SIGMA, 1),
            stage_mod.Options(draws=4))

    def test_every_field_of_the_contract(self):
        for b in self.stage.blocks:
            for part in ("nominal", "measured", "deviation", "uncertainty"):
                for name in stage_mod.CHARACTERISTICS:
                    self.assertIn(name, b[part], "%s %s" % (part, name))
            self.assertEqual(b["nominal"]["chord_method"], "nose-tail")
            self.assertEqual(len(b["nominal"]["centroid_mm"]), 3)
            self.assertEqual(len(b["measured"]["shift_mm"]), 2)
            self.assertEqual(len(b["nominal"]["le_thickness_mm"]),
                             len(b["nominal"]["edge_offsets_mm"]))
            self.assertEqual(b["verdict"], "not judged")
        lb = self.stage.lean_bow
        for key in ("lean_mm_per_mm", "lean_deg", "bow_mm", "bow_magnitude_mm",
                    "largest_bow_section"):
            self.assertIn(key, lb)

    def test_measured_equals_nominal_within_the_issue_figures(self):
        lengths = ("axial_chord_mm", "max_thickness_mm")
        for b in self.stage.blocks:
            d = b["deviation"]
            for name in lengths:
                self.assertLess(abs(d[name]), 0.002, "%s %s" % (b["label"], name))
            for name in ("le_thickness_mm", "te_thickness_mm"):   # 0.5 mm: KERNEL_LIMITS
                self.assertLess(np.max(np.abs(d[name][1:])), 0.002, "%s %s" % (b["label"], name))
            self.assertLess(np.max(np.abs(d["shift_mm"])), 0.002)
            self.assertLess(np.max(np.abs(d["centroid_mm"])), 0.002)
            self.assertLess(abs(d["twist_deg"]), 0.005)
            # form: the noise's own spread, a few sigma
            self.assertLess(b["measured"]["form_mm"], 12 * SENSOR_SIGMA)
            self.assertAlmostEqual(b["measured"]["noise_mm"], SENSOR_SIGMA, delta=0.0004)

    def test_what_the_kernel_reaches_on_noisy_points(self):
        for b in self.stage.blocks:
            d = values.flat(b["deviation"])
            for name, limit in KERNEL_LIMITS.items():
                self.assertLess(abs(d[name]), limit, "%s %s" % (b["label"], name))

    def test_uncertainty_is_stated_and_covers_the_error(self):
        # 4 draws only (the bench takes more): the error within 5 stated sigma.
        for b in self.stage.blocks:
            u = b["uncertainty"]
            for name in ("axial_chord_mm", "max_thickness_mm", "area_mm2", "twist_deg"):
                self.assertGreater(u[name], 0.0)
                self.assertLess(abs(b["deviation"][name]), 5 * u[name] + 1e-4, name)

    def test_the_verdict_is_untouched_without_tolerances(self):
        verdict = {"pass": True, "summary": "PASS: within +-0.040 mm"}
        self.table.airfoil = None
        stage_mod.attach(self.result, self.nominal, self.table, verdict,
                         stage_mod.Options(draws=0))
        self.assertTrue(verdict["pass"])
        self.assertIsNone(verdict["airfoil"]["pass"])
        self.assertIn("airfoil", stage_mod.extras_of(self.table))


class KnownChanges(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = demo_nominal()
        # 0.02 mm: at 0.05 mm a TE of 0.17 mm radius has ~5 points in its +-45 deg zone and
        # the offset part's TE radius read +0.015 instead of +0.020 (0.5 um noise).
        cls.readings = Readings.get(cls.nominal)
        cls.span, _ = sections_mod.span_axis_of(cls.nominal)

    def test_offset_part_reads_twice_the_offset_in_thickness(self):
        stage, _, _ = _stage(self.nominal, _noisy(self.readings["sections"], QUIET_SIGMA, 2,
                                                  move=lambda k, q, n: q + 0.020 * n))
        for b, sec in zip(stage.blocks, stage.sections):
            d = b["deviation"]
            self.assertAlmostEqual(d["max_thickness_mm"], 0.040, delta=0.002)
            self.assertAlmostEqual(d["le_radius_mm"], 0.020, delta=0.005)
            self.assertAlmostEqual(d["te_radius_mm"], 0.020, delta=0.005)
            # The nose-tail chord turns: the offset moves the edge points 0.020 mm along the
            # camber line's end tangents, which are not the chord's direction (0.005-0.01 deg
            # on this blade, so "stagger unchanged within 0.005 deg" is not the geometry).
            n = sec.nominal
            le = n.le_point - 0.020 * n.mcl.le_tangent
            te = n.te_point + 0.020 * n.mcl.te_tangent
            turn = np.degrees(np.arctan2(np.cross(te - le, n.te_point - n.le_point) * -1.0,
                                         (te - le) @ (n.te_point - n.le_point)))
            self.assertAlmostEqual(d["stagger_deg"], turn, delta=0.002)
            self.assertLess(abs(d["twist_deg"]), 0.005)
            # (edge thicknesses are not +0.040: the offset edge point moves 0.020 mm out, so
            # "0.5 mm from the edge" is another, thinner place of the blade)
            # twice the largest |deviation|: the offset and the largest noise (< 5 sigma)
            self.assertGreater(b["measured"]["form_location_mm"], 0.040)
            self.assertLess(b["measured"]["form_location_mm"], 0.040 + 2 * 5 * QUIET_SIGMA)

    def test_turned_section_reads_its_twist(self):
        def turn(k, q, n):
            if k != 1:
                return q
            pivot = q.mean(axis=0)
            R = tf.rotation_from_vector(self.span * np.radians(0.05))
            return (q - pivot) @ R.T + pivot
        stage, _, _ = _stage(self.nominal, _noisy(self.readings["sections"], QUIET_SIGMA, 3,
                                                  move=turn))
        twists = [b["deviation"]["twist_deg"] for b in stage.blocks]
        self.assertAlmostEqual(twists[1], 0.050, delta=0.005)
        self.assertLess(abs(twists[0]), 0.005)
        self.assertLess(abs(twists[2]), 0.005)

    def test_shifted_section_reads_its_shift_and_is_the_bow(self):
        # 0.010 mm across the span, in the section plane.
        across = np.cross(self.span, [1.0, 0.0, 0.0])
        across /= np.linalg.norm(across)
        stage, _, _ = _stage(self.nominal, _noisy(
            self.readings["sections"], QUIET_SIGMA, 4,
            move=lambda k, q, n: q + 0.010 * across if k == 1 else q))
        b = stage.blocks[1]
        frame = stage.sections[1].frame
        shift_3d = frame.vector_to_3d(b["deviation"]["shift_mm"])[0]
        np.testing.assert_allclose(shift_3d, 0.010 * across, atol=0.002)
        for other in (stage.blocks[0], stage.blocks[2]):
            self.assertLess(np.linalg.norm(other["deviation"]["shift_mm"]), 0.002)
        self.assertEqual(stage.lean_bow["largest_bow_section"], b["label"])
        self.assertAlmostEqual(stage.lean_bow["bow_magnitude_mm"][1], 0.010, delta=0.002)


class Tolerances(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = demo_nominal()
        cls.readings = Readings.get(cls.nominal, COARSE_SPACING)
        cls.tmp = tempfile.mkdtemp(prefix="bi-airfoil-")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def _file(self, text, name="chars.csv"):
        path = os.path.join(self.tmp, name)
        with open(path, "w") as fh:
            fh.write(text)
        return path

    def test_judged_characteristics_and_the_failing_one_named(self):
        nominal_t = None
        path = self._file("characteristic,section,lower,upper,nominal\n"
                          "max_thickness_mm,all,-0.01,0.01,\n"
                          "twist_deg,all,-0.02,0.02,\n"
                          # a window the perfect part's ~0 deviation lies outside of
                          "le_thickness_mm[1],2,0.005,0.010,\n"
                          "form_mm,all,,0.05,\n")
        opts = stage_mod.options_from_args(characteristics=path)
        opts.draws = 0
        stage, table, result = _stage(self.nominal, _noisy(self.readings["sections"],
                                                           QUIET_SIGMA, 5), opts)
        self.assertFalse(stage.verdict["pass"])
        self.assertEqual(stage.verdict["failed"], ["section 2: le_thickness_mm[1]"])
        self.assertEqual(stage.verdict["n_judged"], 3 * 3 + 1)
        self.assertEqual(stage.blocks[0]["verdicts"]["max_thickness_mm"], "pass")
        self.assertEqual(stage.blocks[0]["verdicts"]["chord_mm"], "not judged")
        self.assertEqual(stage.blocks[1]["verdict"], "fail")
        self.assertEqual(stage.blocks[0]["verdict"], "pass")
        verdict = {"pass": True, "summary": "PASS: within +-0.040 mm"}
        table.airfoil = stage
        stage_mod.attach(result, self.nominal, table, verdict, opts)
        self.assertFalse(verdict["pass"])
        self.assertIn("le_thickness_mm[1]", verdict["summary"])
        rows = stage_mod.csv_rows(stage.blocks)
        failing = [r for r in rows if r[-1] == "fail"]
        self.assertEqual([(r[0], r[1]) for r in failing], [("2", "le_thickness_mm[1]")])
        del nominal_t

    def test_a_drawing_nominal_overrides_the_cad(self):
        stage0, _, _ = _stage(self.nominal, _noisy(self.readings["sections"], QUIET_SIGMA, 6))
        cad_value = stage0.blocks[0]["nominal"]["max_thickness_mm"]
        path = self._file("characteristic,section,lower,upper,nominal\n"
                          "max_thickness_mm,1,-0.01,0.01,%.6f\n" % (cad_value + 0.05),
                          name="override.csv")
        opts = stage_mod.options_from_args(characteristics=path)
        opts.draws = 0
        stage, _, _ = _stage(self.nominal, _noisy(self.readings["sections"], QUIET_SIGMA, 6),
                             opts)
        b = stage.blocks[0]
        self.assertAlmostEqual(b["nominal"]["max_thickness_mm"], cad_value + 0.05, places=6)
        self.assertAlmostEqual(b["deviation"]["max_thickness_mm"], -0.05, delta=0.002)
        self.assertEqual(stage.verdict["failed"], ["section 1: max_thickness_mm"])

    def test_bad_files_name_the_file_and_row(self):
        from BladeInspect import cli
        cases = [("characteristic,section,lower,upper\nthickness,all,-1,1\n", "row 2"),
                 ("characteristic,section,lower,upper\nchord_mm,all,-1,x\n", "row 2"),
                 ("characteristic,section,lower,upper\nchord_mm,all,-1,1\n"
                  "chord_mm,all,1,-1\n", "row 3"),
                 ("name,lower\nchord_mm,1\n", "row 1"),
                 ("characteristic,section,lower,upper\nchord_mm,9,-1,1\n", "row 2")]
        import io
        import contextlib
        for k, (text, row) in enumerate(cases):
            path = self._file(text, name="bad%d.csv" % k)
            out = os.path.join(self.tmp, "out%d" % k)
            err = io.StringIO()
            with contextlib.redirect_stderr(err):
                code = cli.main(["airfoil", "--out", out, "--section-heights", "30,70",
                                 "--characteristics", path])
            lines = err.getvalue().strip().splitlines()
            self.assertEqual(code, 2, text)
            self.assertEqual(len(lines), 1, lines)
            self.assertIn(path, lines[0])
            self.assertIn(row, lines[0])
            self.assertFalse(os.path.exists(out))


class ReportAndBatch(unittest.TestCase):
    """One blade through `batch` (hence `report`): its points in an unknown frame, registered,
    the airfoil stage through the report's hooks, a toleranced characteristic failing."""

    @classmethod
    def setUpClass(cls):
        from BladeInspect.inspection.batch import run_batch
        nominal = demo_nominal()
        readings = Readings.get(nominal, COARSE_SPACING)
        pts = _noisy(readings["sections"], SENSOR_SIGMA, 8)
        xyz = np.vstack(pts)
        label = np.concatenate([np.full(len(p), k + 1) for k, p in enumerate(pts)])
        pose = tf.make_transform(tf.rotation_from_vector([0.3, -0.2, 0.5]), [10.0, -5.0, 3.0])
        measured = tf.apply_transform(np.linalg.inv(pose), xyz)
        cls.tmp = tempfile.mkdtemp(prefix="bi-airfoil-batch-")
        scans = os.path.join(cls.tmp, "scans")
        os.makedirs(scans)
        np.savetxt(os.path.join(scans, "blade1.csv"), np.column_stack([measured, label]),
                   delimiter=",", header="x,y,z,section", comments="",
                   fmt=["%.7f", "%.7f", "%.7f", "%d"])
        chars = os.path.join(cls.tmp, "chars.csv")
        with open(chars, "w") as fh:
            fh.write("characteristic,section,lower,upper\n"
                     "max_thickness_mm,all,-0.01,0.01\n"
                     "area_mm2,2,0.5,1.0\n")
        opts = stage_mod.options_from_args(characteristics=chars)
        opts.draws = 0
        cls.out = os.path.join(cls.tmp, "lot")
        cls.summary = run_batch(None, scans, cls.out, RunOptions.of(airfoil=opts), workers=1)
        with open(os.path.join(cls.out, "blade1", "result.json")) as fh:
            cls.doc = json.load(fh)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_result_json_has_the_blocks_and_the_verdict_names_the_failure(self):
        self.assertEqual([b["label"] for b in self.doc["airfoil"]], ["1", "2", "3"])
        self.assertIn("largest_bow_section", self.doc["lean_bow"])
        self.assertFalse(self.doc["verdict"]["pass"])
        self.assertIn("section 2: area_mm2", self.doc["verdict"]["summary"])
        self.assertEqual(self.doc["airfoil_verdict"]["failed"], ["section 2: area_mm2"])
        for b in self.doc["airfoil"]:
            # the pose found by the registration leaves the sections where the CAD has them
            self.assertLess(np.max(np.abs(b["deviation"]["shift_mm"])), 0.002)
            self.assertLess(abs(b["deviation"]["twist_deg"]), 0.005)
            self.assertLess(abs(b["deviation"]["max_thickness_mm"]), 0.002)
            self.assertEqual(b["verdicts"]["max_thickness_mm"], "pass")

    def test_report_and_lot_summary(self):
        with open(os.path.join(self.out, "blade1", "report.html")) as fh:
            text = fh.read()
        self.assertIn("Airfoil characteristics", text)
        self.assertIn("section 3 airfoil", text)
        self.assertIn("shift and twist", text)
        # the report names the failure as the tables do; result.json keeps the field name
        text = html.unescape(text)
        self.assertIn("Airfoil: FAIL, 1 of 4 characteristics: Section 2: Section area", text)
        self.assertNotIn("section 2: area_mm2", text)
        with open(os.path.join(self.out, "summary_airfoil.csv")) as fh:
            rows = list(csv.DictReader(fh))
        self.assertEqual({r["file"] for r in rows}, {"blade1.csv"})
        self.assertEqual(len(rows), 3 * (13 + 6 + 3 + 2))
        failing = [(r["section"], r["characteristic"]) for r in rows if r["verdict"] == "fail"]
        self.assertEqual(failing, [("2", "area_mm2")])
        self.assertEqual(self.summary["rows"][0]["verdict"], "fail")


class NominalOnlyCommand(unittest.TestCase):
    def test_airfoil_command_on_the_demo_blade(self):
        import FreeCAD
        import Part
        from BladeInspect import cli
        from BladeInspect.cad.sections import cut
        tmp = tempfile.mkdtemp(prefix="bi-airfoil-cli-")
        self.addCleanup(shutil.rmtree, tmp, True)
        out = os.path.join(tmp, "out")
        code = cli.main(["airfoil", "--out", out, "--section-heights", "30,70",
                         "--engine-axis", "1,0,0", "--edge-offsets", "0.5,1"])
        self.assertEqual(code, 0)
        self.assertEqual(sorted(os.listdir(out)), ["airfoil.csv", "airfoil.json"])
        with open(os.path.join(out, "airfoil.json")) as fh:
            doc = json.load(fh)
        self.assertEqual([b["label"] for b in doc["airfoil"]], ["1", "2"])
        nominal = demo_nominal()
        for b, plane in zip(doc["airfoil"], stage_mod.nominal_planes(nominal, (30, 70))):
            self.assertIsNone(b["measured"])
            self.assertEqual(b["nominal"]["edge_offsets_mm"], [0.5, 1.0])
            self.assertEqual(len(b["nominal"]["le_thickness_mm"]), 2)
            # centroid against OCC's centre of mass of the section's face
            loop = max(cut(nominal.shape, plane.origin, plane.normal), key=len)
            face = Part.Face(Part.makePolygon([FreeCAD.Vector(*p) for p in loop]))
            np.testing.assert_allclose(b["nominal"]["centroid_mm"],
                                       np.array(face.CenterOfMass), atol=1e-3)
            self.assertGreater(b["nominal"]["area_mm2"], face.Area)
            self.assertLess(b["nominal"]["area_mm2"] - face.Area, 1e-3)
        with open(os.path.join(out, "airfoil.csv")) as fh:
            rows = list(csv.reader(fh))
        self.assertEqual(rows[0], list(stage_mod.CSV_HEADER))
        # per section: 13 scalars, 2 + 2 edge thicknesses, 3 centroid, 2 shift
        self.assertEqual(len(rows) - 1, 2 * (13 + 4 + 3 + 2))
        self.assertTrue(all(r[3] == "" and r[-1] == "not judged" for r in rows[1:]))

    def test_engine_axis_forms(self):
        self.assertEqual(stage_mod.parse_engine_axis("-y"), (-0.0, -1.0, -0.0))
        np.testing.assert_allclose(stage_mod.parse_engine_axis("2,0,0"), (1, 0, 0))
        from BladeInspect.core.errors import InputError
        for bad in ("w", "1,0", "0,0,0", "nan,0,1"):
            with self.assertRaises(InputError):
                stage_mod.parse_engine_axis(bad)


if __name__ == "__main__":
    unittest.main()
