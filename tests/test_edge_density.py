"""Issue 15 item 7 through the planner `inspect` uses (measurement.planning.plan_sections with
its default edge rule): each planned section has at least the rule's count of points in each
edge's +-45 degree zone, the count worked out here from the circle fit's Fisher information
(not from core.airfoil's closed form); and a perfect demo blade read on the simulated rig at
the planned points, at the sensor's noise, gives LE and TE radii within 5 um of the CAD's edge
circles, fitted here to the CAD's own cut (OCC) by a geometric least-squares circle of this
module's over the +-45 degree zone about the nominal camber line's outward direction (the
definition's axis; the demo's noses are not circular, so the zone's axis matters)."""
import unittest

import numpy as np
from scipy.optimize import least_squares

from BladeInspect.cad.airfoil_sections import airfoil_section
from BladeInspect.cad.sections import cut
from BladeInspect.core import airfoil as kernel
from BladeInspect.inspection import airfoil_stage as stage_mod
from BladeInspect.inspection import sections as sections_mod
from BladeInspect.measurement import planning
from BladeInspect.rig.sensor import SensorModel
from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose_of
from tests.helpers import demo_nominal, planned_readings_result

HEIGHTS = (15.0, 85.0)
ZONE_DEG = 45.0
RADIUS_TOLERANCE_MM = 0.005
SEEDS = (3, 11)


def fisher_points_needed(noise_mm, radius_sigma_mm, zone_deg):
    """Points evenly spread in angle over +-zone_deg of a circle that a geometric circle fit
    needs for its radius's 1 sigma to be at most radius_sigma_mm: the radius's variance is
    noise^2 [(J^T J)^-1]_rr with rows (cos t, sin t, 1), n times a limit f^2 / n for many
    points."""
    t = np.radians(np.linspace(-zone_deg, zone_deg, 20001))
    J = np.column_stack([np.cos(t), np.sin(t), np.ones_like(t)])
    f2 = len(t) * np.linalg.inv(J.T @ J)[2, 2]
    return int(np.ceil(f2 * (noise_mm / radius_sigma_mm) ** 2))


def fit_circle(xy):
    c0 = xy.mean(axis=0)
    r0 = np.linalg.norm(xy - c0, axis=1).mean()

    def residual(p):
        return np.linalg.norm(xy - p[:2], axis=1) - p[2]
    p = least_squares(residual, np.r_[c0, r0], xtol=1e-15, ftol=1e-15, gtol=1e-15).x
    return p[:2], p[2]


def zone_mask(xy, centre, radius, axis):
    v = xy - centre
    d = np.linalg.norm(v, axis=1)
    return (np.abs(d - radius) < 0.5 * radius) & ((v @ axis) >= d * np.cos(np.radians(ZONE_DEG)))


def cad_edges(nominal, frame, nominal_chars):
    """[(centre, radius, zone axis)] of the LE and TE in ``frame``: the circle this module
    fits to the CAD's own cut (OCC, points 1 um apart) over the +-ZONE_DEG zone about the
    edge's outward camber-line direction (the definition's axis, from the nominal's camber
    line), re-fitted until the zone stops changing."""
    loops = [p for p in cut(nominal.shape, frame.origin, frame.normal, 0.001)
             if np.linalg.norm(p[0] - p[-1]) < 1e-9]
    xy = max((frame.to_2d(p) for p in loops), key=len)
    mcl = nominal_chars.mcl
    out = []
    for circle, axis in ((nominal_chars.le_circle, -mcl.le_tangent),
                         (nominal_chars.te_circle, mcl.te_tangent)):
        centre, radius = np.asarray(circle.center), circle.radius
        zone = None
        for _ in range(30):
            mask = zone_mask(xy, centre, radius, axis)
            if zone is not None and np.array_equal(mask, zone):
                break
            zone = mask
            centre, radius = fit_circle(xy[mask])
        out.append((centre, radius, axis))
    return out


class EdgeDensityInTheInspectPlan(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = demo_nominal()
        cls.sensor = SensorModel()
        axis, _ = sections_mod.span_axis_of(cls.nominal)
        cls.axis = axis
        cls.runs = []
        for seed in SEEDS:
            truth = random_fixture_pose_of(cls.nominal, np.random.default_rng(seed), axis)
            rig = SimulatedRig(cls.nominal, truth, sensor=cls.sensor, seed=seed)
            plan = planning.plan_sections(
                cls.nominal, truth, HEIGHTS, rig.sensor, rig.limits, span_axis=axis,
                kinematics=rig.kinematics,
                edge_radius_sigma_mm=planning.DEFAULT_EDGE_RADIUS_SIGMA_MM)
            cls.runs.append((rig, plan))
        cls.frames, cls.edges = [], []
        for sec in cls.runs[0][1].sections:
            xy, frame = airfoil_section(cls.nominal.shape, sec.plane_point, sec.plane_normal)
            cls.frames.append(frame)
            cls.edges.append(cad_edges(cls.nominal, frame, kernel.characteristics(xy)))

    def test_rule_count_is_the_fisher_count(self):
        needed = fisher_points_needed(self.sensor.sigma_ref, 0.002, ZONE_DEG)
        info = self.runs[0][1].info["edge_density"]
        self.assertEqual(info["points_per_zone"], needed)
        self.assertEqual(info["radius_sigma_mm"], 0.002)
        self.assertAlmostEqual(info["noise_mm"], self.sensor.sigma_ref, places=12)

    def test_each_edge_zone_holds_the_rule_count(self):
        needed = fisher_points_needed(self.sensor.sigma_ref,
                                      planning.DEFAULT_EDGE_RADIUS_SIGMA_MM, ZONE_DEG)
        for _, plan in self.runs:
            for sec, frame, edges in zip(plan.sections, self.frames, self.edges):
                xy = frame.to_2d(sec.target_cad)
                for centre, radius, axis in edges:
                    n = int(zone_mask(xy, centre, radius, axis).sum())
                    self.assertGreaterEqual(n, needed, "%g %%: %d points on an edge of radius "
                                            "%.3f mm" % (sec.height_pct, n, radius))

    def test_rule_off_plans_the_plain_spacing(self):
        rig, plan = self.runs[0]
        plain = planning.plan_sections(self.nominal, rig.table_to_cad, HEIGHTS, rig.sensor,
                                       rig.limits, span_axis=self.axis,
                                       kinematics=rig.kinematics, edge_radius_sigma_mm="off")
        self.assertIsNone(plain.info["edge_density"])
        self.assertLess(plain.n_points, plan.n_points / 2)
        for bad in (-0.001, "x", float("nan")):
            with self.assertRaises(Exception) as ctx:
                planning.edge_radius_sigma(bad)
            self.assertIn("--edge-radius-sigma", str(ctx.exception))
        self.assertIsNone(planning.edge_radius_sigma(0))

    def test_an_edge_under_two_spots_is_said(self):
        spot = self.sensor.spot
        edges = [[{"edge": "LE", "radius_mm": 0.2, "spacing_mm": 1e-3},
                  {"edge": "TE", "radius_mm": 1.5 * spot, "spacing_mm": 1e-4}]]
        info = planning.edge_density_info((self.sensor.sigma_ref, 0.002), edges, [90.0], spot)
        self.assertEqual(len(info["warnings"]), 1)
        self.assertIn("TE radius", info["warnings"][0])
        self.assertEqual(self.runs[0][1].info["edge_density"]["warnings"], [])

    def test_perfect_part_edge_radii_within_5_um_of_the_cad(self):
        for rig, plan in self.runs:
            result, _ = planned_readings_result(self.nominal, rig, plan)
            table = sections_mod.section_table(result, self.nominal, heights_pct=HEIGHTS,
                                               span_axis=self.axis)
            stage = stage_mod.run_stage(self.nominal, stage_mod.planes_of_table(table),
                                        stage_mod.Options(draws=0), result, table.span_axis)
            for block, sr, sec, (le, te) in zip(stage.blocks, stage.sections,
                                                 plan.sections, self.edges):
                self.assertLess(abs((sr.plane.origin - sec.plane_point) @ sec.plane_normal),
                                1e-6)
                for key, truth in (("le_radius_mm", le[1]), ("te_radius_mm", te[1])):
                    self.assertAlmostEqual(block["measured"][key], truth,
                                           delta=RADIUS_TOLERANCE_MM,
                                           msg="%s at %g %%" % (key, sr.plane.height_pct))


if __name__ == "__main__":
    unittest.main()
