"""The rig calibration's uncertainty in the airfoil characteristics' u (issue 16 item 4): a
section's in-plane location moves one for one with a translation of its points (a fact of the
geometry, checked here on the kernel with a known translation), so with a calibration term
much larger than everything else the shift's stated u must be that term; a thickness does not
move with a translation, so its u must not grow. The stage takes the term from the verdict's
measurement model (RIG.json's calibration_uncertainty_mm), and the task file's key holds it."""
import unittest

import numpy as np

from BladeInspect.inspection import airfoil_stage as stage_mod
from BladeInspect.inspection import airfoil_task
from BladeInspect.inspection import sections as sections_mod
from BladeInspect.measurement.planning import nominal_section
from tests.helpers import demo_nominal
from tests.test_airfoil_pipeline import SENSOR_SIGMA, _noisy, _result

HEIGHT = 50.0
CALIBRATION_MM = 0.02      # 20x the pose's 1 um: the shift's u is then the calibration's
DRAWS = 48                 # a 1 sigma of 48 draws is known to 1 / sqrt(94) = 10 %
# Characteristics that do not move with a translation and are measured at this 0.1 mm
# sampling (its edge zones hold 7 and 3 points: the edge radii and chord are withheld).
MEASURED = ("max_thickness_mm", "area_mm2")


class CalibrationInTheAirfoilU(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = demo_nominal()
        planes = stage_mod.nominal_planes(cls.nominal, (HEIGHT,))
        section = nominal_section(cls.nominal, planes[0].origin, planes[0].normal, 0.1)[:2]
        xyz = np.vstack(_noisy([section], SENSOR_SIGMA, 3))
        cls.result = _result(cls.nominal, xyz)
        cls.table = sections_mod.section_table(cls.result, cls.nominal, heights_pct=(HEIGHT,),
                                               band=0.01)
        cls.planes = stage_mod.planes_of_table(cls.table)

    def stage(self, calibration_mm, draws=DRAWS, result=None):
        opts = stage_mod.Options(draws=draws, calibration_mm=calibration_mm, seed=4)
        return stage_mod.run_stage(self.nominal, self.planes, opts, result or self.result,
                                   self.table.span_axis)

    def test_a_translation_moves_the_shift_one_for_one(self):
        # the geometry the model rests on, without the model: points moved by t in the plane
        normal = self.planes[0].normal / np.linalg.norm(self.planes[0].normal)
        t = np.cross(normal, [0.0, 0.0, 1.0] if abs(normal[2]) < 0.9 else [1.0, 0.0, 0.0])
        t = 0.01 * t / np.linalg.norm(t)
        still = self.stage(None, draws=0)
        moved = self.stage(None, draws=0,
                           result=_result(self.nominal, self.result.points_cad + t))
        shift = np.subtract(moved.blocks[0]["measured"]["shift_mm"],
                            still.blocks[0]["measured"]["shift_mm"])
        self.assertAlmostEqual(float(np.linalg.norm(shift)), 0.01, delta=0.0002)
        for name in MEASURED:
            self.assertAlmostEqual(moved.blocks[0]["measured"][name],
                                   still.blocks[0]["measured"][name], delta=0.0005, msg=name)

    def test_the_shift_u_is_the_calibration_and_the_thickness_u_does_not_grow(self):
        without = self.stage(None).blocks[0]["uncertainty"]
        with_cal = self.stage(CALIBRATION_MM).blocks[0]["uncertainty"]
        for k in range(2):
            self.assertLess(without["shift_mm"][k], 0.2 * CALIBRATION_MM)
            expected = np.hypot(CALIBRATION_MM, without["shift_mm"][k])
            self.assertGreater(with_cal["shift_mm"][k], 0.72 * expected)
            self.assertLess(with_cal["shift_mm"][k], 1.3 * expected)
        for name in MEASURED:
            # a model that moved the points along their normals by the term would read ~20 um
            self.assertLess(with_cal[name], 1.45 * without[name] + 1e-4, name)

    def test_attach_takes_the_term_from_the_verdicts_measurement_model(self):
        for model, said in (({"calibration_mm": CALIBRATION_MM}, "rig calibration's 0.02 mm"),
                            ({"calibration_mm": None}, "rig calibration not included"),
                            (None, "rig calibration not included")):
            verdict = {"pass": True, "summary": "PASS"}
            if model is not None:
                verdict["measurement_model"] = model
            stage_mod.attach(self.result, self.nominal, self.table, verdict,
                             stage_mod.Options(draws=8, seed=4))
            stage = self.table.airfoil
            self.assertIn(said, stage.settings["uncertainty_method"])
            shift_u = max(stage.blocks[0]["uncertainty"]["shift_mm"])
            if model and model["calibration_mm"]:
                self.assertGreater(shift_u, 0.4 * CALIBRATION_MM)
            else:
                self.assertLess(shift_u, 0.2 * CALIBRATION_MM)

    def test_the_task_key_holds_the_term_only_when_given(self):
        plain = airfoil_task.task_key(self.nominal, stage_mod.Options(), self.result)
        given = airfoil_task.task_key(self.nominal,
                                        stage_mod.Options(calibration_mm=CALIBRATION_MM),
                                        self.result)
        self.assertNotIn("calibration_mm", plain)      # files made without one stay valid
        self.assertEqual(given.pop("calibration_mm"), CALIBRATION_MM)
        self.assertEqual(given, plain)
        self.assertNotEqual(airfoil_task.digest(plain),
                            airfoil_task.digest(airfoil_task.task_key(
                                self.nominal, stage_mod.Options(calibration_mm=0.001),
                                self.result)))


if __name__ == "__main__":
    unittest.main()
