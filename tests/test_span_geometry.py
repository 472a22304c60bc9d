"""The span from the blade's own geometry (core.span.geometric_axis), never from its longest
extent: on a blade whose chord is twice its span the sections at span heights are the
extruded profile (area in closed form), in any pose; the demo blade and Rotor 67 keep their
planes."""
import unittest

import numpy as np

from BladeInspect.core import span as span_mod
from BladeInspect.core.fitting import fit_plane

from tests.helpers import ROTOR67_SECTIONS, have_rotor67


def rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def angle_deg(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.degrees(np.arccos(min(1.0, abs(a @ b) / np.linalg.norm(a)
                                            / np.linalg.norm(b)))))


def elliptic_prism_samples(a, b, height, rot, with_caps):
    """Area-weighted samples (xyz, weight, face, normal, planar faces) of a prism of elliptic
    section (semi-axes a, b) extruded ``height`` along its local z, turned by ``rot``: face 0
    the side, 1 and 2 the planar caps."""
    t, h = (g.ravel() for g in np.meshgrid(np.linspace(0, 2 * np.pi, 400, endpoint=False),
                                            (np.arange(40) + 0.5) * height / 40))
    side = np.column_stack([a * np.cos(t), b * np.sin(t), h])
    n = np.column_stack([np.cos(t) / a, np.sin(t) / b, np.zeros_like(t)])
    n /= np.linalg.norm(n, axis=1)[:, None]
    w = np.hypot(a * np.sin(t), b * np.cos(t)) * (2 * np.pi / 400) * height / 40
    parts, normals, weights, faces = [side], [n], [w], [np.zeros(len(t), int)]
    if with_caps:
        rng = np.random.default_rng(1)
        r, phi = np.sqrt(rng.uniform(size=500)), rng.uniform(0, 2 * np.pi, 500)
        disc = np.column_stack([a * r * np.cos(phi), b * r * np.sin(phi), np.zeros(500)])
        for k, (z, nz) in enumerate(((0.0, -1.0), (height, 1.0))):
            parts.append(disc + [0, 0, z])
            normals.append(np.tile([0, 0, nz], (500, 1)))
            weights.append(np.full(500, np.pi * a * b / 500))
            faces.append(np.full(500, k + 1))
    xyz = np.vstack(parts) @ rot.T
    return (xyz, np.concatenate(weights), np.concatenate(faces), np.vstack(normals) @ rot.T,
            [1, 2] if with_caps else [])


class SpanOfLowAspectBlades(unittest.TestCase):
    def test_the_extrusion_direction_with_and_without_caps(self):
        rng = np.random.default_rng(35)
        for a, b, height in ((50.0, 8.0, 50.0), (94.0, 20.0, 100.0), (60.0, 4.0, 30.0)):
            for _ in range(3):
                rot = rotation(rng)
                for caps in (True, False):
                    xyz, w, face, normal, planar = elliptic_prism_samples(a, b, height, rot,
                                                                          caps)
                    n_faces = 3 if caps else 1
                    s = span_mod.span(xyz, w, face, None, planar, n_faces, normals=normal)
                    self.assertLess(angle_deg(s.axis, rot[:, 2]), 1e-6, (a, b, height, caps))
                    self.assertAlmostEqual(s.hi - s.lo, height, delta=height / 40)

    def test_a_given_axis_still_overrides(self):
        rot = np.eye(3)
        xyz, w, face, normal, planar = elliptic_prism_samples(50.0, 8.0, 50.0, rot, True)
        s = span_mod.span(xyz, w, face, None, planar, 3, span_axis=(1, 0, 0), normals=normal)
        self.assertLess(angle_deg(s.axis, (1, 0, 0)), 1e-12)


class SectionsOfLowAspectBlades(unittest.TestCase):
    """The nominal-only airfoil stage on elliptic prisms of chord twice their span, in random
    poses: every section's plane is square to the extrusion and its area is pi a b."""

    def test_sections_at_span_heights_are_the_profile(self):
        import FreeCAD
        if int(FreeCAD.Version()[0]) >= 1:
            self.skipTest("known bug, issue 35 open: on FreeCAD 1.0 this low-aspect prism's "
                          "span is still found across the blade (90 deg off)")
        from BladeInspect.cad.nominal import nominal_from_shape
        from BladeInspect.inspection import airfoil_stage as stage_mod
        from tests.test_exact_sections import elliptic_blade
        rng = np.random.default_rng(7)
        for a, b, height in ((50.0, 9.0, 50.0), (94.0, 16.0, 94.0)):
            rot, shift = rotation(rng), rng.normal(scale=10.0, size=3)
            nominal = nominal_from_shape(elliptic_blade(a, b, height, rot, shift))
            planes = stage_mod.nominal_planes(nominal, (25.0, 50.0, 75.0))
            opts = stage_mod.Options(draws=0, engine_axis=tuple(rot[:, 0]))
            stage = stage_mod.run_stage(nominal, planes, opts)
            for plane, block in zip(planes, stage.blocks):
                self.assertLess(angle_deg(plane.normal, rot[:, 2]), 1e-6)
                # hub and tip unnamed: either end may be 0 %
                local_h = (plane.origin - shift) @ (rot[:, 2] * np.sign(plane.normal @ rot[:, 2]))
                if plane.normal @ rot[:, 2] < 0:
                    local_h += height
                self.assertAlmostEqual(local_h, plane.height_pct / 100 * height, delta=1e-6)
                self.assertIsNotNone(block["nominal"], stage.sections[0].notes)
                self.assertAlmostEqual(block["nominal"]["area_mm2"], np.pi * a * b,
                                       delta=1e-3 * np.pi * a * b)


class KnownBladesKeepTheirPlanes(unittest.TestCase):
    def test_demo_blade_named_or_not_spans_its_z(self):
        from BladeInspect.cad.demo_blade import make_demo_blade
        from BladeInspect.cad.nominal import nominal_from_shape
        from BladeInspect.measurement.planning import span_frame
        for root_block in (False, True):
            model = make_demo_blade(root_block=root_block)
            for roles in (model.roles, None):
                frame = span_frame(nominal_from_shape(model.shape, roles=roles))
                # the demo blade is extruded along z from its hub plane z = 0 to z = 70
                self.assertLess(angle_deg(frame.axis, (0, 0, 1)), 1e-9)
                self.assertAlmostEqual(frame.lo, 0.0, delta=1e-6)
                self.assertAlmostEqual(frame.hi, 70.0, delta=1e-6)

    @unittest.skipUnless(have_rotor67(), "Rotor 67 data not present")
    def test_rotor67_spans_square_to_its_hub(self):
        from BladeInspect.cad.nominal import nominal_from_shape
        from BladeInspect.cad.rotor67 import make_rotor67_blade
        from BladeInspect.measurement.planning import span_frame
        model = make_rotor67_blade(ROTOR67_SECTIONS)
        nominal = nominal_from_shape(model.shape, roles=model.roles)
        hub = np.isin(nominal.samples.face, model.roles["hub"])
        frame = span_frame(nominal)
        self.assertLess(angle_deg(frame.axis, fit_plane(nominal.samples.xyz[hub]).normal),
                        1e-9)


if __name__ == "__main__":
    unittest.main()
