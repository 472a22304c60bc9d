"""The rig calibration's error at each reading (issue 16 item 4, per reading): an axis known only
to its covariance places a reading taken at angle a at K(K'^-1(q, a), a) instead of q, so each
view of the part is displaced differently; the registration takes up the rigid part common to
all. Checked against the closed form of an axis offset ((R(a)^T - I) delta), against the exact
non-linear placement for small random errors, and by the take-up's defining properties (a field
from one view is rigid and vanishes; what is left of any field is orthogonal to every rigid
motion in the fit's weighted normal residuals); then that the airfoil draws use it in place of
the isotropic translation when the readings carry their angles, and that RIG.json's axis is read
and checked."""
import json
import os
import tempfile
import unittest

import numpy as np

from BladeInspect.core import bias_take_up as core_take_up
from BladeInspect.core import stats
from BladeInspect.core import transforms as tf
from BladeInspect.core.errors import InputError
from BladeInspect.inspection import uncertainty as uncertainty_mod
from BladeInspect.inspection.result import RegistrationResult
from BladeInspect.measurement.calibration_uncertainty import error_fields, kinematics_with
from BladeInspect.rig.kinematics import RigKinematics

COVARIANCE = np.diag([0.002, 0.0015, 3e-5, 3e-5]) ** 2   # mm, mm, rad, rad (1 sigma squared)


def _turn_about_y(angle_deg):
    a = np.radians(angle_deg)
    return np.array([[np.cos(a), 0.0, np.sin(a)], [0.0, 1.0, 0.0],
                     [-np.sin(a), 0.0, np.cos(a)]])


def _result(points_cad, normals, angles, to_cad, weights=None):
    n = len(points_cad)
    d = np.zeros(n)
    return RegistrationResult(
        measured_to_cad=to_cad, points_cad=points_cad, deviation=d,
        inlier=np.ones(n, bool), closest=points_cad, normal=normals, face=np.zeros(n, int),
        snr=None, columns={"angle_deg": np.asarray(angles, dtype=float)}, n_rows_skipped=0,
        rms_mm=0.0, pose_covariance=np.diag([1e-6] * 3 + [1e-12] * 3),
        center=points_cad.mean(axis=0), pose_uncertainty_mm=1e-3,
        deviation_stats=stats.deviation_statistics(d), coarse={}, icp_weights=weights)


def _part(rng, n=1500):
    """Points on an ellipsoid 40 x 120 x 15 mm about (5, 60, -3) (table frame), its normals
    (every rigid motion measured), turned into a CAD frame by a random rigid motion."""
    u = rng.normal(size=(n, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    axes = np.array([20.0, 60.0, 7.5])
    table = u * axes + [5.0, 60.0, -3.0]
    normals = u / axes
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    R = tf.rotation_from_vector(rng.normal(size=3) * 0.7)
    to_cad = np.eye(4)
    to_cad[:3, :3], to_cad[:3, 3] = R, rng.normal(size=3) * 30.0
    return table, table @ R.T + to_cad[:3, 3], normals @ R.T, to_cad


class ErrorFields(unittest.TestCase):
    def test_an_axis_offset_is_the_closed_form(self):
        rng = np.random.default_rng(1)
        q = rng.uniform(-80, 80, size=(40, 3))
        angles = rng.choice([0.0, 30.0, 95.0, 180.0, 270.5], size=40)
        G = error_fields(RigKinematics(), np.zeros(4), q, angles)
        for i in range(len(q)):
            # rig.kinematics: machine = R (q - p) + p, table = R^T (m - p) + p, R the
            # right-handed turn about the axis (+Y); an axis at p + delta reads q at
            # q + (R^T - I) delta
            closed = _turn_about_y(angles[i]).T - np.eye(3)
            np.testing.assert_allclose(G[i][:, 0], closed[:, 0], atol=1e-6)
            np.testing.assert_allclose(G[i][:, 1], closed[:, 2], atol=1e-6)

    def test_the_fields_are_the_exact_placement_linearised(self):
        rng = np.random.default_rng(2)
        believed_parameters = np.array([0.12, -0.2, 0.001, -0.0015])
        believed = kinematics_with(RigKinematics(), believed_parameters)
        for trial in range(5):
            q = rng.uniform(-100, 100, size=(60, 3))
            angles = rng.uniform(0, 360, size=60).round(1)
            d = rng.multivariate_normal(np.zeros(4), COVARIANCE)
            true = kinematics_with(RigKinematics(), believed_parameters + d)
            exact = np.vstack([believed.table_point(true.machine_point_of_table(q[i:i + 1], a), a)
                               for i, a in enumerate(angles)]) - q
            linear = error_fields(RigKinematics(), believed_parameters, q, angles) @ d
            scale = np.abs(exact).max()
            self.assertGreater(scale, 1e-4)
            np.testing.assert_allclose(linear, exact, atol=1e-3 * scale + 1e-9)


class CalibrationFields(unittest.TestCase):
    AXIS = {"parameters": [0.0, 0.0, 0.0, 0.0], "covariance": COVARIANCE.tolist()}

    def test_one_view_is_rigid_and_taken_up_whole(self):
        rng = np.random.default_rng(3)
        table, cad, normals, to_cad = _part(rng)
        raw = error_fields(RigKinematics(), np.zeros(4), table, np.full(len(table), 40.0))
        left = uncertainty_mod.calibration_fields(
            _result(cad, normals, np.full(len(cad), 40.0), to_cad), self.AXIS)
        for k in range(4):
            self.assertGreater(np.abs(raw[:, :, k]).max(), 1e-3)
            self.assertLess(np.abs(left[:, :, k]).max(), 1e-8 * np.abs(raw[:, :, k]).max()
                            + 1e-12)

    def test_what_is_left_of_many_views_is_orthogonal_to_every_rigid_motion(self):
        rng = np.random.default_rng(4)
        table, cad, normals, to_cad = _part(rng)
        angles = rng.choice(np.arange(0.0, 360.0, 22.5), size=len(cad))
        weights = rng.uniform(0.2, 2.0, size=len(cad))
        result = _result(cad, normals, angles, to_cad, weights)
        left = uncertainty_mod.calibration_fields(result, self.AXIS)
        raw = np.einsum("ij,njk->nik", to_cad[:3, :3],
                        error_fields(RigKinematics(), np.zeros(4), table, angles))
        # the fit's points: not the edge feet (a beam too oblique to its normal to be read)
        w = weights * core_take_up.takes_part(
            cad, normals, uncertainty_mod.beam_directions(result), weights,
            uncertainty_mod.SensorModel().max_incidence_rad)
        self.assertGreater(np.count_nonzero(w), len(cad) // 3)
        J = core_take_up.rigid_jacobian(cad, normals, result.center)
        for k in range(4):
            residual = np.einsum("ij,ij->i", left[:, :, k], normals)
            # the weighted least squares' normal equations hold
            self.assertLess(np.abs(J.T @ (w * residual)).max(),
                            1e-9 * (np.abs(J).T @ (w * np.abs(residual))).max() + 1e-12)
            # and raw - left is one rigid motion t + w x (p - c)
            taken = raw[:, :, k] - left[:, :, k]
            A = np.zeros((3 * len(cad), 6))
            arm = cad - result.center
            for axis in range(3):
                A[axis::3, axis] = 1.0
                e = np.zeros(3)
                e[axis] = 1.0
                A[:, 3 + axis] = np.cross(e, arm).reshape(-1)
            r = np.linalg.lstsq(A, taken.reshape(-1), rcond=None)[0]
            self.assertLess(np.abs(A @ r - taken.reshape(-1)).max(),
                            1e-7 * np.abs(taken).max() + 1e-12)
        # several views: something is left (the term is not taken up whole)
        self.assertGreater(np.abs(left).max(), 0.05 * np.abs(raw).max())

    def test_without_angles_there_is_no_field(self):
        rng = np.random.default_rng(5)
        _, cad, normals, to_cad = _part(rng, 100)
        result = _result(cad, normals, np.zeros(len(cad)), to_cad)
        result.columns = {}
        self.assertIsNone(uncertainty_mod.calibration_fields(result, self.AXIS))
        self.assertIsNone(uncertainty_mod.calibration_fields(
            _result(cad, normals, np.zeros(len(cad)), to_cad), None))


class InTheAirfoilDraws(unittest.TestCase):
    """The demo section read from two sides (0 and 180 deg): an axis error moves the two sides
    apart, which no rigid motion takes up, and the section's shift and thickness read it."""
    AXIS = {"parameters": [0.0, 0.0, 0.0, 0.0],
            "covariance": (np.diag([0.04, 0.04, 4e-4, 4e-4]) ** 2).tolist()}
    DRAWS = 48           # u known to 10 %
    MOVES = 64           # the direct simulation's 1 sigma to 9 %

    @classmethod
    def setUpClass(cls):
        from BladeInspect.inspection import airfoil_stage as stage_mod
        from BladeInspect.inspection import sections as sections_mod
        from BladeInspect.measurement.planning import nominal_section
        from tests.helpers import demo_nominal
        from tests.test_airfoil_pipeline import SENSOR_SIGMA, _noisy, _result as pipeline_result
        cls.stage_mod = stage_mod
        cls.nominal = demo_nominal()
        planes = stage_mod.nominal_planes(cls.nominal, (50.0,))
        section = nominal_section(cls.nominal, planes[0].origin, planes[0].normal, 0.1)[:2]
        xyz = np.vstack(_noisy([section], SENSOR_SIGMA, 3))
        cls.result = pipeline_result(cls.nominal, xyz)
        side = cls.result.normal[:, 0] > 0
        cls.result.columns = {"angle_deg": np.where(side, 0.0, 180.0)}
        cls.table = sections_mod.section_table(cls.result, cls.nominal, heights_pct=(50.0,),
                                               band=0.01)
        cls.planes = stage_mod.planes_of_table(cls.table)

    def stage(self, axis, draws, result=None):
        opts = self.stage_mod.Options(draws=draws, calibration_axis=axis, seed=4)
        return self.stage_mod.run_stage(self.nominal, self.planes, opts, result or self.result,
                                        self.table.span_axis)

    def test_the_draws_state_the_scatter_of_the_moved_readings(self):
        import copy
        fields = uncertainty_mod.calibration_fields(self.result, self.AXIS)
        chol = np.linalg.cholesky(np.asarray(self.AXIS["covariance"]))
        rng = np.random.default_rng(7)
        values = []
        for _ in range(self.MOVES):
            moved = copy.copy(self.result)
            moved.points_cad = self.result.points_cad + fields @ (chol @ rng.standard_normal(4))
            block = self.stage(None, 0, moved).blocks[0]["measured"]
            values.append([block["shift_mm"][0], block["shift_mm"][1],
                           block["max_thickness_mm"]])
        moved_sd = np.std(values, axis=0, ddof=1)
        without = self.stage(None, self.DRAWS).blocks[0]["uncertainty"]
        stage = self.stage(self.AXIS, self.DRAWS)
        self.assertIn("axis covariance", stage.settings["uncertainty_method"])
        with_axis = stage.blocks[0]["uncertainty"]
        stated = [with_axis["shift_mm"][0], with_axis["shift_mm"][1],
                  with_axis["max_thickness_mm"]]
        alone = [without["shift_mm"][0], without["shift_mm"][1], without["max_thickness_mm"]]
        for name, s, a, m in zip(("shift x", "shift y", "max thickness"), stated, alone,
                                 moved_sd):
            self.assertGreater(m, 3.0 * a, name)     # the axis error dominates the row
            expected = np.hypot(a, m)
            self.assertGreater(s, 0.7 * expected, name)
            self.assertLess(s, 1.3 * expected, name)


    def test_without_angles_the_translation_serves(self):
        import copy
        no_angles = copy.copy(self.result)
        no_angles.columns = {}
        opts = self.stage_mod.Options(draws=8, calibration_axis=self.AXIS, calibration_mm=0.02,
                                      seed=4)
        stage = self.stage_mod.run_stage(self.nominal, self.planes, opts, no_angles,
                                         self.table.span_axis)
        self.assertIn("as an in-plane shift", stage.settings["uncertainty_method"])
        self.assertGreater(min(stage.blocks[0]["uncertainty"]["shift_mm"]), 0.01)

    def test_the_task_key_holds_the_axis_only_when_given(self):
        from BladeInspect.inspection import airfoil_task
        plain = airfoil_task.task_key(self.nominal, self.stage_mod.Options(), self.result)
        given = airfoil_task.task_key(
            self.nominal, self.stage_mod.Options(calibration_axis=self.AXIS), self.result)
        self.assertNotIn("calibration_axis", plain)
        self.assertEqual(given.pop("calibration_axis"), self.AXIS)
        self.assertEqual(given, plain)
        other = dict(self.AXIS, covariance=(2.0 * np.asarray(self.AXIS["covariance"])).tolist())
        self.assertNotEqual(
            airfoil_task.digest(airfoil_task.task_key(
                self.nominal, self.stage_mod.Options(calibration_axis=self.AXIS), self.result)),
            airfoil_task.digest(airfoil_task.task_key(
                self.nominal, self.stage_mod.Options(calibration_axis=other), self.result)))


class RigFileAxis(unittest.TestCase):
    def write(self, data):
        fd, path = tempfile.mkstemp(suffix=".json")
        with os.fdopen(fd, "w") as f:
            json.dump(data, f)
        self.addCleanup(os.remove, path)
        return path

    def test_the_axis_is_read_with_the_term(self):
        path = self.write({"calibration_uncertainty_mm": 0.0002,
                           "calibration_parameter_values": [0.1, 0.2, 0.0, 0.0],
                           "calibration_covariance": COVARIANCE.tolist()})
        model = uncertainty_mod.model_from_rig_file(path)
        self.assertEqual(model.calibration_axis["parameters"], [0.1, 0.2, 0.0, 0.0])
        np.testing.assert_array_equal(model.calibration_axis["covariance"], COVARIANCE)
        self.assertEqual(model.to_json()["calibration_axis"], model.calibration_axis)
        old = self.write({"calibration_uncertainty_mm": 0.0002})   # a file from before
        self.assertIsNone(uncertainty_mod.model_from_rig_file(old).calibration_axis)

    def test_a_wrong_axis_is_a_one_line_error(self):
        for bad in ({"calibration_parameter_values": [0.1, 0.2, 0.0],
                     "calibration_covariance": COVARIANCE.tolist()},
                    {"calibration_parameter_values": [0.1, 0.2, 0.0, 0.0],
                     "calibration_covariance": (-COVARIANCE).tolist()},
                    {"calibration_parameter_values": [0.1, 0.2, 0.0, 0.0],
                     "calibration_covariance": "none"},
                    {"calibration_parameter_values": [0.1, 0.2, 0.0, float("nan")],
                     "calibration_covariance": COVARIANCE.tolist()}):
            path = self.write(dict(bad, calibration_uncertainty_mm=0.0002))
            with self.assertRaises(InputError) as ctx:
                uncertainty_mod.model_from_rig_file(path)
            self.assertIn("calibration_covariance", str(ctx.exception))
            self.assertNotIn("\n", str(ctx.exception))


if __name__ == "__main__":
    unittest.main()
