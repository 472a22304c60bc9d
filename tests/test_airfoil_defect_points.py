"""The airfoil characteristics see a defect the robust fit rejected, and not the isolated
readings it rejected (inspection.airfoil_stage.measured_surface).

A quiet sensor reads the demo blade's planned sections in the rig's true pose, with a 30 um
bump on the suction side at the first section and a few isolated gross readings of +0.2 mm.
The fit's rejection is then imposed as the robust ICP does it (every reading more than 12 um
off, the bump's and the gross ones), so the truth is known without registering: the section's
form_location_mm (twice its largest |deviation|) must read the bump, 2 x 30 um, and not the
gross readings, 2 x 200 um. Before the fix the stage measured the fit's inliers only and read
about 2 x 12 um, a defect lost with a confident face.
"""
import unittest

import numpy as np

from BladeInspect.inspection import airfoil_stage as stage_mod
from BladeInspect.inspection import sections as sections_mod
from BladeInspect.measurement import planning
from BladeInspect.rig.sensor import SensorModel
from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose_of
from tests.helpers import demo_nominal, planned_readings_result, suction_bump_at

HEIGHTS = (30.0, 70.0)
BUMP_MM = 0.030
BUMP_RADIUS_MM = 6.0
GROSS_MM = 0.2
REJECTED_ABOVE_MM = 0.012
SEED = 5
# The quiet sensor's readings scatter by a few um; the bump's crest is sampled, not hit.
READ_BACK_MM = 0.006


class DefectPointsCount(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        nominal = cls.nominal = demo_nominal()
        axis, bump = suction_bump_at(nominal, HEIGHTS[0], BUMP_RADIUS_MM, BUMP_MM)
        truth = random_fixture_pose_of(nominal, np.random.default_rng(SEED), axis)
        rig = SimulatedRig(nominal, truth, sensor=SensorModel(accuracy=0.0005), seed=SEED,
                           error_field=bump)
        plan = planning.plan_sections(nominal, truth, HEIGHTS, rig.sensor, rig.limits,
                                      span_axis=axis, kinematics=rig.kinematics)
        result, _ = planned_readings_result(nominal, rig, plan)
        table = sections_mod.section_table(result, nominal, heights_pct=HEIGHTS, span_axis=axis)
        rng = np.random.default_rng(SEED)
        first = table.sections[0].point_index
        # Isolated gross readings: far apart along the section, pushed out along the normal.
        cls.gross = rng.choice(first[::50], 4, replace=False)
        result.points_cad[cls.gross] += GROSS_MM * result.normal[cls.gross]
        result.deviation[cls.gross] += GROSS_MM
        result.inlier = np.abs(result.deviation) <= REJECTED_ABOVE_MM
        cls.result, cls.table = result, table
        cls.bump_points = np.flatnonzero((result.deviation > REJECTED_ABOVE_MM)
                                         & (result.deviation < 0.1))

    def stage(self):
        return stage_mod.run_stage(self.nominal, stage_mod.planes_of_table(self.table),
                                   stage_mod.Options(draws=0), self.result,
                                   self.table.span_axis)

    def test_the_case_is_what_it_claims(self):
        self.assertGreater(len(self.bump_points), 20)
        self.assertFalse(self.result.inlier[self.bump_points].any())
        self.assertFalse(self.result.inlier[self.gross].any())

    def test_the_bump_is_measured_and_the_gross_readings_are_not(self):
        block = self.stage().blocks[0]
        form_location = block["measured"]["form_location_mm"]
        self.assertAlmostEqual(form_location, 2 * BUMP_MM, delta=2 * READ_BACK_MM)
        self.assertGreater(block["measured"]["form_mm"], BUMP_MM - READ_BACK_MM)
        counted = stage_mod.measured_surface(self.result)
        self.assertTrue(counted[self.bump_points].all())
        self.assertFalse(counted[self.gross].any())

    def test_a_section_without_a_defect_reads_its_noise(self):
        block = self.stage().blocks[1]
        self.assertLess(block["measured"]["form_location_mm"], 2 * REJECTED_ABOVE_MM)


if __name__ == "__main__":
    unittest.main()
