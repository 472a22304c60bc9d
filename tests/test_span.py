"""The span every command's section heights are percentages of (core.span): one rule for the
planner and the analysis, and a root block or platform modelled with the blade never moves it."""
import json
import os
import shutil
import subprocess
import tempfile
import unittest

import numpy as np

from BladeInspect.core import span as span_mod
from BladeInspect.core import transforms as tf

from tests.helpers import REPO, ROTOR67_SECTIONS, demo_nominal, have_rotor67


def tube_with_block(axis, rng, with_caps=True):
    """Samples of an elliptic tube along ``axis`` from 0 to 50 mm, planar caps at both ends,
    and a block's top face 8 mm below the lower cap: (xyz, weight, face, planar faces)."""
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    u = np.cross(axis, [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(axis, u)
    # a regular grid, so that the principal axis is the tube's exactly; cell centres fall
    # short of the ends
    t, h = (g.ravel() for g in np.meshgrid(np.linspace(0, 2 * np.pi, 80, endpoint=False),
                                            np.linspace(0.3, 49.7, 50)))
    tube = h[:, None] * axis + 12 * np.cos(t)[:, None] * u + 3 * np.sin(t)[:, None] * v
    parts, faces = [tube], [np.zeros(len(tube), int)]
    r = np.sqrt(rng.uniform(0, 1, 300))       # the caps' samples need no symmetry
    a = rng.uniform(0, 2 * np.pi, 300)
    disc = 12 * (r * np.cos(a))[:, None] * u + 3 * (r * np.sin(a))[:, None] * v
    if with_caps:
        parts += [disc, disc + 50 * axis]
        faces += [np.full(300, 1), np.full(300, 2)]
    block = -8 * axis + 3 * disc
    parts.append(block)
    faces.append(np.full(300, 3))
    xyz = np.vstack(parts)
    return xyz, np.ones(len(xyz)), np.concatenate(faces), [1, 2, 3] if with_caps else [3]


class TestSpanRule(unittest.TestCase):
    def test_unnamed_caps_count_and_a_block_does_not(self):
        rng = np.random.default_rng(3)
        for trial in range(5):
            axis = tf.rotation_from_vector(rng.normal(size=3) * 0.3) @ [0, 0, 1.0]
            xyz, w, face, planar = tube_with_block(axis, rng)
            s = span_mod.span(xyz, w, face, {}, planar, 4)
            self.assertGreater(abs(s.axis @ axis), 1 - 1e-12)
            sign = np.sign(s.axis @ axis)
            lo, hi = sorted([sign * s.lo, sign * s.hi])
            self.assertAlmostEqual(lo, 0.0, places=9)    # the caps, not the block at -8
            self.assertAlmostEqual(hi, 50.0, places=9)

    def test_without_caps_the_extent_is_the_airfoil_faces(self):
        rng = np.random.default_rng(4)
        xyz, w, face, planar = tube_with_block([0, 0, 1.0], rng, with_caps=False)
        s = span_mod.span(xyz, w, face, {}, planar, 4)
        h = xyz[face == 0] @ s.axis
        self.assertEqual((s.lo, s.hi), (h.min(), h.max()))

    def test_named_hub_and_tip_orient_a_given_axis(self):
        rng = np.random.default_rng(5)
        xyz, w, face, planar = tube_with_block([0, 0, 1.0], rng)
        roles = {"suction": [0], "hub": [1], "tip": [2]}
        s = span_mod.span(xyz, w, face, roles, planar, 4, span_axis=[0, 0, -2.0])
        np.testing.assert_allclose(s.axis, [0, 0, 1.0])
        self.assertAlmostEqual(s.lo, 0.0, places=9)
        self.assertAlmostEqual(s.hi, 50.0, places=9)


class TestSpanOfCADs(unittest.TestCase):
    def test_demo_blade_with_and_without_its_root_block(self):
        from BladeInspect.cad.demo_blade import BladeParams
        from BladeInspect.inspection import sections
        from BladeInspect.inspection.pipeline import load_nominal
        span = BladeParams().span
        for nominal in (demo_nominal(), load_nominal("demo:root-block")):
            axis, (lo, hi) = sections.span_axis_of(nominal)
            np.testing.assert_allclose(axis, [0, 0, 1.0], atol=1e-12)
            self.assertAlmostEqual(lo, 0.0, places=9)
            self.assertAlmostEqual(hi, span, places=9)

    def test_a_step_file_of_the_root_block_part_keeps_the_blades_span(self):
        # No face names survive STEP: the rule must tell the caps from the block by itself.
        from BladeInspect.cad.demo_blade import make_demo_blade
        from BladeInspect.inspection import sections
        from BladeInspect.inspection.pipeline import load_nominal
        tmp = tempfile.mkdtemp(prefix="bi-span-")
        try:
            spans = []
            for name, root in (("plain", False), ("root", True)):
                path = os.path.join(tmp, name + ".step")
                make_demo_blade(root_block=root).shape.exportStep(path)
                # one sample spacing, so that the blade faces get the same samples in both
                spans.append(sections.span_axis_of(load_nominal(path, sample_spacing=0.5)))
            np.testing.assert_allclose(spans[0][0], spans[1][0], atol=1e-12)
            np.testing.assert_allclose(spans[0][1], spans[1][1], atol=1e-9)
        finally:
            shutil.rmtree(tmp)

    @unittest.skipUnless(have_rotor67(), "no shared Rotor 67 data")
    def test_planner_and_analysis_cut_the_same_planes(self):
        # They had a rule each, 19 degrees apart on Rotor 67.
        from BladeInspect.inspection import sections
        from BladeInspect.inspection.pipeline import load_nominal
        from BladeInspect.measurement import planning
        nominal = load_nominal(ROTOR67_SECTIONS)
        axis, (lo, hi) = sections.span_axis_of(nominal)
        p_axis, origin, p_lo, p_hi = planning.span_axis_of(nominal)
        np.testing.assert_allclose(p_axis, axis, atol=1e-15)
        for h in (0.0, 37.0, 100.0):
            planned = origin + p_axis * (p_lo + (p_hi - p_lo) * h / 100.0)
            self.assertAlmostEqual(planned @ axis, lo + (hi - lo) * h / 100.0, places=9)


class TestDatumFitFromTheCommandLine(unittest.TestCase):
    def test_simulate_and_register_the_root_block_part_by_its_datums(self):
        tmp = tempfile.mkdtemp(prefix="bi-datum-cli-")
        try:
            sim, reg = os.path.join(tmp, "sim"), os.path.join(tmp, "reg")
            scans, lot = os.path.join(tmp, "scans"), os.path.join(tmp, "lot")
            points = os.path.join(sim, "points.csv")
            for args in (["simulate", "--cad", "demo:root-block", "--out", sim, "--seed", "3"],
                         ["register", "--cad", "demo:root-block", "--points", points,
                          "--out", reg, "--fit", "datum"],
                         # the batch and the report's FreeCAD document take the name too
                         ["batch", "--cad", "demo:root-block", "--scans", scans, "--out", lot,
                          "--workers", "1", "--no-airfoil", "--fit", "datum"]):
                if args[0] == "batch":
                    os.makedirs(scans)
                    shutil.copy(points, os.path.join(scans, "blade1.csv"))
                done = subprocess.run([os.path.join(REPO, "bladeinspect")] + args,
                                      capture_output=True, text=True, timeout=300)
                self.assertEqual(done.returncode, 0, done.stderr[-2000:])
            with open(os.path.join(reg, "result.json")) as fh:
                result = json.load(fh)
            with open(os.path.join(sim, "result.json")) as fh:
                truth = np.asarray(json.load(fh)["simulation"]["truth_measured_to_cad"])
            fit = result["fit"]
            self.assertEqual(fit["objective"], "datum")
            self.assertEqual([d["order"] for d in fit["datums"]],
                             ["primary", "secondary", "tertiary"])
            self.assertTrue(all(d["n_points"] > 100 for d in fit["datums"]))
            # The datum frame's pose against the simulation's truth, at the root block's and
            # the blade's far corners: a few noise-limited micrometres at most.
            corners = np.array([[-30, -15, -25], [40, 20, 70], [-30, 20, 70], [40, -15, -25]],
                               float)
            moved = tf.apply_transform(np.asarray(fit["measured_to_cad"]) @
                                       tf.invert_transform(truth), corners)
            self.assertLess(np.abs(moved - corners).max(), 0.002)
            import FreeCAD
            doc = FreeCAD.openDocument(os.path.join(lot, "blade1", "inspection.FCStd"))
            try:
                blade = doc.getObject("DemoBlade")
                self.assertTrue(blade.RootBlock)
                self.assertEqual(len(blade.Shape.Faces), 10)   # 4 of the blade, 6 of the block
            finally:
                FreeCAD.closeDocument(doc.Name)
        finally:
            shutil.rmtree(tmp)


if __name__ == "__main__":
    unittest.main()
