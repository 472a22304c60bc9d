"""cad.raycast against answers it does not compute itself: closed forms (a cylinder met at
grazing incidence across its seam, a translated box) and OpenCASCADE (distToShape of the hit,
of the ray's stretch before it and of missing rays) on the small twisted blade. Covers the
paths the cache of direction grids opens: the same direction again, rays parallel to a grid
(decided in its plane) and slanted ones (Moller-Trumbore on segment traces), several
directions in one call, few rays bucketed without a kept grid, and two nominals of the same
shape at different places."""
import unittest
from unittest import mock

import numpy as np

import FreeCAD
import Part

from BladeInspect.cad import raycast
from BladeInspect.core import raycast as ray_kernel
from BladeInspect.cad.nominal import nominal_from_shape
from tests.test_distance import twisted_blade

V = FreeCAD.Vector


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


class TwistedBladeAgainstOCC(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = nominal_from_shape(twisted_blade())
        cls.shape = cls.nominal.shape

    def rays_towards(self, rng, n, direction, spread=0.0):
        """n rays aimed at random points of the blade's box from 60 mm back along direction
        (each turned off it by up to ``spread`` radians)."""
        lo, hi = self.nominal.bbox_corners.min(axis=0), self.nominal.bbox_corners.max(axis=0)
        aim = rng.uniform(lo - 1.0, hi + 1.0, (n, 3))
        d = unit(np.asarray(direction, float) + rng.uniform(-spread, spread, (n, 3)))
        return aim - 60.0 * d, d

    def assert_first_hits(self, o, d, t, face, nrm):
        """Each hit on the CAD (OCC distance), nothing of the CAD on the ray before it, the
        outward normal against the ray, the face index OCC names; each miss far from the CAD."""
        self.assertGreater(np.count_nonzero(np.isfinite(t)), len(t) // 4)
        for i in range(len(t)):
            if np.isfinite(t[i]):
                x = o[i] + t[i] * d[i]
                dist, _, info = self.shape.distToShape(Part.Vertex(V(*x)))
                self.assertLess(dist, 1e-9, "ray %d: hit off the surface" % i)
                before = Part.LineSegment(V(*o[i]), V(*(o[i] + (t[i] - 1e-4) * d[i]))).toShape()
                self.assertGreater(self.shape.distToShape(before)[0], 1e-7, "ray %d: not first" % i)
                self.assertLess(np.dot(nrm[i], d[i]), 0.0)
                if info[0][0] == "Face":
                    occ_n = np.array(self.shape.Faces[info[0][1]].normalAt(*info[0][2]))
                    self.assertEqual(face[i], info[0][1])
                    np.testing.assert_allclose(nrm[i], occ_n, atol=1e-9)
            else:
                ray = Part.LineSegment(V(*o[i]), V(*(o[i] + 200.0 * d[i]))).toShape()
                # grazing misses are allowed within the tessellation's deflection
                self.assertGreater(self.shape.distToShape(ray)[0], 0.0, "ray %d: missed" % i)

    def test_parallel_rays_few_then_many(self):
        """Few rays of a new direction bucket only the triangles around them (no grid kept);
        a direction with many rays keeps its whole grid, which later calls reuse, few rays or
        not. Both give the same answers, bit for bit."""
        rng = np.random.default_rng(31)
        o, d = self.rays_towards(rng, 50, [0.3, -1.0, 0.2])
        self.nominal._tessellation = None
        t, face, nrm = self.nominal.raycast(o, d)
        grids = self.nominal._tessellation._grids
        self.assertEqual(len(grids), 0)
        self.assert_first_hits(o, d, t, face, nrm)
        with mock.patch.object(ray_kernel, "FEW_RAYS_PER_TRIANGLE", 0):
            kept = self.nominal.raycast(o[::-1], d[::-1])
        self.assertEqual(len(grids), 1)
        again = self.nominal.raycast(o, d)
        self.assertEqual(len(grids), 1)
        for tk, fk in ((kept[0][::-1], kept[1][::-1]), again[:2]):
            np.testing.assert_array_equal(tk, t)
            np.testing.assert_array_equal(fk, face)

    def test_slanted_rays_in_one_group(self):
        rng = np.random.default_rng(32)
        o, d = self.rays_towards(rng, 50, [-0.2, -1.0, 0.1], spread=0.008)
        t, face, nrm = self.nominal.raycast(o, d)
        self.assert_first_hits(o, d, t, face, nrm)

    def test_rays_from_all_sides(self):
        rng = np.random.default_rng(33)
        d = unit(rng.normal(size=(60, 3)))
        lo, hi = self.nominal.bbox_corners.min(axis=0), self.nominal.bbox_corners.max(axis=0)
        o = rng.uniform(lo, hi, (60, 3)) - 60.0 * d
        t, face, nrm = self.nominal.raycast(o, d)
        self.assert_first_hits(o, d, t, face, nrm)

    def test_several_directions_in_one_call_match_one_call_each(self):
        """A planning cast mixes the beams of several rotary angles: each group's result is
        the one its rays get alone (which the tests above check against OCC)."""
        rng = np.random.default_rng(34)
        angles = np.radians([0.0, 5.0, 10.0, 60.0, 200.0])
        dirs = [np.array([np.sin(a), -np.cos(a), 0.1]) for a in angles]
        parts = [self.rays_towards(rng, 400, dd) for dd in dirs]
        o = np.vstack([p[0] for p in parts])
        d = np.vstack([p[1] for p in parts])
        t, face, nrm = self.nominal.raycast(o, d)
        for k, (ok, dk) in enumerate(parts):
            rows = slice(400 * k, 400 * (k + 1))
            tk, fk, nk = self.nominal.raycast(ok, dk)
            np.testing.assert_allclose(t[rows], tk, atol=1e-12, equal_nan=True)
            np.testing.assert_array_equal(face[rows], fk)
        self.assert_first_hits(o[::40], d[::40], t[::40], face[::40], nrm[::40])


class ClosedForms(unittest.TestCase):
    def test_cylinder_grazing_and_across_the_seam(self):
        """Rays across a cylinder of radius 5 at offsets up to grazing, some through its seam:
        the first hit is the entry root sqrt(R^2 - b^2) before the axis' foot, never the exit
        root Newton may slide to near the silhouette."""
        r = 5.0
        nominal = nominal_from_shape(Part.makeCylinder(r, 20.0))
        rng = np.random.default_rng(35)
        n = 600
        phi = rng.uniform(0, 2 * np.pi, n)
        d = np.column_stack([np.cos(phi), np.sin(phi), np.zeros(n)])
        side = np.column_stack([-np.sin(phi), np.cos(phi), np.zeros(n)])
        b = r * np.sqrt(rng.uniform(0, 1, n)) * rng.choice([-1.0, 1.0], n)
        b[:100] = np.sign(b[:100]) * r * (1 - 10 ** rng.uniform(-6, -2, 100))   # grazing
        z = rng.uniform(1.0, 19.0, n)
        o = b[:, None] * side - 30.0 * d + np.column_stack([np.zeros(n), np.zeros(n), z])
        jumps = []
        original = ray_kernel._other_root

        def other_root(*args):
            starts = original(*args)
            jumps.append(np.count_nonzero(np.isfinite(starts[:, 0])))
            return starts
        # Some of these rays' Newton lands on the far root first: the jump to the near one
        # (not OCC) must then find the entry root.
        with mock.patch.object(ray_kernel, "_other_root", other_root), \
                mock.patch.object(raycast, "_occ_ray", side_effect=AssertionError("OCC used")):
            t, face, nrm = nominal.raycast(o, d)
        self.assertGreater(sum(jumps), 0)
        expected = 30.0 - np.sqrt(r * r - b * b)
        hit = np.isfinite(t)
        # Everything but the last deflection before the silhouette is hit, and hit exactly.
        defl = nominal._tessellation.deflection
        self.assertTrue(np.all(hit[np.abs(b) < r - 2 * defl]))
        np.testing.assert_allclose(t[hit], expected[hit], atol=1e-9)
        x = o[hit] + t[hit, None] * d[hit]
        np.testing.assert_allclose(nrm[hit], x * [1, 1, 0] / r, atol=1e-9)

    def test_translated_copies_have_their_own_grids(self):
        """Two nominals of one box, the second moved up 3 mm: the same rays from above meet
        it 3 mm earlier; a grid kept by the first must not answer for the second."""
        box = Part.makeBox(10, 10, 10)
        moved = box.copy()
        moved.translate(V(0, 0, 3))
        first, second = nominal_from_shape(box), nominal_from_shape(moved)
        rng = np.random.default_rng(36)
        o = np.column_stack([rng.uniform(0.5, 9.5, 200), rng.uniform(0.5, 9.5, 200),
                             np.full(200, 30.0)])
        d = np.tile([0.0, 0.0, -1.0], (200, 1))
        t1, _, _ = first.raycast(o, d)
        t2, _, _ = second.raycast(o, d)
        np.testing.assert_allclose(t1, 20.0, atol=1e-12)
        np.testing.assert_allclose(t2, 17.0, atol=1e-12)

    @mock.patch.object(ray_kernel, "FEW_RAYS_PER_TRIANGLE", 0)
    def test_grid_cache_is_bounded(self):
        nominal = nominal_from_shape(Part.makeSphere(5.0))
        rng = np.random.default_rng(37)
        for _ in range(ray_kernel.MAX_CACHED_GRIDS + 4):
            d = unit(rng.normal(size=3))
            o = -20.0 * d + np.zeros((3, 3))
            t, _, _ = nominal.raycast(o, np.tile(d, (3, 1)))
            np.testing.assert_allclose(t, 15.0, atol=1e-9)
        self.assertEqual(len(nominal._tessellation._grids), ray_kernel.MAX_CACHED_GRIDS)


if __name__ == "__main__":
    unittest.main()
