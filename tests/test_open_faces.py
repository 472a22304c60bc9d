"""Surface-only CAD: a blade given as its two open sides (no caps), in STEP, IGES and BREP, with
either side's parameterisation reversed, reads every deviation with "+" = excess material.

The truth is independent of the code under test: the closed solid that the same two sides make
with planar caps (surface_build.close_sides, as the demo blade is built), its faces' OCC outward
normals (Face.normalAt on the solid) and OCC's Solid.isInside.
"""
import contextlib
import io
import json
import os
import shutil
import tempfile
import unittest

import numpy as np

import FreeCAD
import Part

from BladeInspect import cli
from BladeInspect.cad import demo_blade
from BladeInspect.cad.load import load_nominal
from BladeInspect.cad.nominal import nominal_from_shape
from BladeInspect.cad.surface_build import close_sides, interpolate_grid
from BladeInspect.core import transforms as tf
from BladeInspect.core.errors import InputError
from tests.helpers import demo_nominal, face_points

# A blade other than the built-in one (more twist, fewer sections), so nothing is shared.
PARAMS = demo_blade.BladeParams(twist_deg=35.0, n_sections=7, camber_root=0.1, sweep=5.0)
BUMP_MM = 0.05
EXACT_MM = 1e-6


def _side_faces(reverse=(False, False)):
    """Suction and pressure faces lofted through PARAMS' sections; ``reverse[k]`` builds side
    k with its u direction (along the chord) reversed: same surface, opposite normal."""
    fractions = np.linspace(0.0, 1.0, PARAMS.n_sections)
    suction, pressure = [], []
    for s in fractions:
        up, lo, u = demo_blade.section_points(PARAMS, s)
        suction.append(up)
        pressure.append(lo)
    v = fractions * PARAMS.span
    faces = []
    for grid, rev in zip((np.array(suction), np.array(pressure)), reverse):
        if rev:
            faces.append(Part.Face(interpolate_grid(grid[:, ::-1], 1.0 - u[::-1], v)))
        else:
            faces.append(Part.Face(interpolate_grid(grid, u, v)))
    return faces, v


def _truth_solid():
    faces, v = _side_faces()
    hub = [Part.Edge(f.Surface.vIso(v[0])) for f in faces]
    tip = [Part.Edge(f.Surface.vIso(v[-1])) for f in faces]
    solid, (i_s, i_p, _, _) = close_sides(faces[0], faces[1], hub, tip, planar_caps=True)
    return solid, [solid.Faces[i_s], solid.Faces[i_p]]


def _surface_points(face, n, rng, margin=0.05):
    """(points (n, 3), OCC outward normals (n, 3)) at random parameters inside the face."""
    return face_points(face, n, rng, margin)[:2]


def _is_inside(solid, points):
    return np.array([solid.isInside(FreeCAD.Vector(*p), 1e-9, True) for p in points])


def _write(shape, path):
    ext = os.path.splitext(path)[1]
    {".step": shape.exportStep, ".igs": shape.exportIges, ".brep": shape.exportBrep}[ext](path)


class OpenFacesCase(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="bladeinspect-open-")
        cls.solid, cls.truth_sides = _truth_solid()
        rng = np.random.default_rng(13)
        # Per side: points on it and the solid's outward normal there.
        cls.on_side = [_surface_points(f, 60, rng) for f in cls.truth_sides]

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    _nominals = {}

    def open_nominal(self, reverse, ext):
        """The Nominal of the two sides, ``reverse`` as _side_faces, written to and read
        from a file of type ``ext`` (None: in memory). Built once per run."""
        key = (reverse, ext)
        if key not in self._nominals:
            shape = Part.makeCompound(_side_faces(reverse)[0])
            if ext is None:
                self._nominals[key] = nominal_from_shape(shape)
            else:
                path = os.path.join(self.tmp, "sides-%d%d%s" % (reverse + (ext,)))
                _write(shape, path)
                self._nominals[key] = load_nominal(path)
        return self._nominals[key]

    def expected_orientations(self, reverse):
        """Per side: "outward" where the file face's own OCC normal agrees with the solid's
        outward normal, else "flipped"."""
        out = []
        for face, (p, n) in zip(_side_faces(reverse)[0], self.on_side):
            uv = face.Surface.parameter(FreeCAD.Vector(*p[0]))
            file_normal = np.array(tuple(face.normalAt(*uv)))
            out.append("outward" if np.dot(file_normal, n[0]) > 0 else "flipped")
        return out


class TestOpenSidesAreTurnedOutward(OpenFacesCase):
    # Each file format with a different side reversed, and both (and neither) in memory.
    VARIANTS = [((True, False), ".step"), ((False, True), ".igs"), ((True, True), ".brep"),
                ((False, False), None)]

    def test_a_bump_reads_plus_its_height_on_both_sides(self):
        for reverse, ext in self.VARIANTS:
            nominal = self.open_nominal(reverse, ext)
            self.assertEqual(len(nominal.faces), 2)
            for k, (p, n) in enumerate(self.on_side):
                with self.subTest(reverse=reverse, format=ext, side=k):
                    bump = nominal.signed_distance(p + BUMP_MM * n)
                    dent = nominal.signed_distance(p - BUMP_MM * n)
                    np.testing.assert_allclose(bump.distance, BUMP_MM, atol=EXACT_MM)
                    np.testing.assert_allclose(dent.distance, -BUMP_MM, atol=EXACT_MM)
                    # The reported normals are the solid's outward ones.
                    self.assertGreater(np.min(np.einsum("ij,ij->i", bump.normal, n)), 0.999)

    def test_the_record_says_what_was_flipped(self):
        """cad_faces' orientation is "flipped" exactly where the file's normal points into the
        solid (judged by OCC's normals of the file face against the solid's)."""
        for reverse, ext in self.VARIANTS:
            nominal = self.open_nominal(reverse, ext)
            records = nominal.cad_faces
            self.assertEqual([r["index"] for r in records], [0, 1])
            for k, (record, expected) in enumerate(zip(records,
                                                       self.expected_orientations(reverse))):
                with self.subTest(reverse=reverse, format=ext, side=k):
                    self.assertEqual(record["rule"], "ray parity")
                    self.assertEqual(record["orientation"], expected)
                    self.assertGreaterEqual(record["confidence"], 0.9)
            self.assertEqual(nominal.face_side_warnings, [])

    def test_signs_agree_with_the_solids_inside_test(self):
        nominal = self.open_nominal((False, False), None)
        rng = np.random.default_rng(5)
        points = []
        for face in self.truth_sides:
            p, n = _surface_points(face, 50, rng, margin=0.02)
            points.append(p + rng.choice([-1, 1], len(p))[:, None]
                          * rng.uniform(0.005, 0.3, len(p))[:, None] * n)
        points = np.concatenate(points)
        inside = _is_inside(self.solid, points)
        self.assertTrue(0 < inside.sum() < len(points))
        d = nominal.signed_distance(points).distance
        np.testing.assert_array_equal(d < 0, inside)

    def test_fast_path_and_occ_fallback_agree(self):
        nominal = self.open_nominal((False, True), None)
        rng = np.random.default_rng(8)
        p, n = self.on_side[0][0][:20], self.on_side[0][1][:20]
        q, m = self.on_side[1][0][:20], self.on_side[1][1][:20]
        points = np.concatenate([p + rng.uniform(-0.2, 0.2, (20, 1)) * n,
                                 q + rng.uniform(-0.2, 0.2, (20, 1)) * m])
        fast = nominal.signed_distance(points)
        occ = nominal.signed_distance_occ(points)
        np.testing.assert_allclose(fast.distance, occ.distance, atol=EXACT_MM)
        self.assertGreater(np.min(np.einsum("ij,ij->i", fast.normal, occ.normal)), 0.999)

    def test_rays_meet_the_outward_side(self):
        nominal = self.open_nominal((False, True), ".igs")
        for p, n in self.on_side:
            t, face, normal = nominal.raycast(p + 3.0 * n, -n)
            np.testing.assert_allclose(t, 3.0, atol=1e-6)
            self.assertGreater(np.min(np.einsum("ij,ij->i", normal, n)), 0.999)


class TestUndecidedAndUserFlips(OpenFacesCase):
    def test_a_single_open_face_is_undecided_and_said_so(self):
        faces, _ = _side_faces()
        nominal = nominal_from_shape(Part.makeCompound([faces[1]]))
        (record,) = nominal.cad_faces
        self.assertEqual(record["orientation"], "undecided")
        self.assertLess(record["confidence"], 0.5)
        (warning,) = nominal.face_side_warnings
        self.assertIn("face 0", warning)
        self.assertIn("--flip-face 0", warning)
        flipped = nominal_from_shape(Part.makeCompound([faces[1]]), flip_faces=[0])
        self.assertEqual(flipped.cad_faces[0]["rule"], "--flip-face")
        self.assertEqual(flipped.cad_faces[0]["automatic"]["orientation"], "undecided")
        p, n = self.on_side[1]
        a = nominal.signed_distance(p + BUMP_MM * n).distance
        b = flipped.signed_distance(p + BUMP_MM * n).distance
        np.testing.assert_allclose(b, -a, atol=1e-12)
        np.testing.assert_allclose(np.abs(a), BUMP_MM, atol=EXACT_MM)

    def test_flipping_a_decided_face_is_obeyed_and_warned(self):
        faces, _ = _side_faces()
        nominal = nominal_from_shape(Part.makeCompound(faces), flip_faces=[1])
        p, n = self.on_side[1]
        np.testing.assert_allclose(nominal.signed_distance(p + BUMP_MM * n).distance,
                                   -BUMP_MM, atol=EXACT_MM)
        (warning,) = nominal.face_side_warnings
        self.assertIn("face 1", warning)
        self.assertIn("overrides", warning)

    def test_bad_flips_are_refused(self):
        faces, _ = _side_faces()
        with self.assertRaisesRegex(InputError, r"--flip-face 5: the CAD has 2 faces"):
            nominal_from_shape(Part.makeCompound(faces), flip_faces=[5])
        with self.assertRaisesRegex(InputError, "closed solid"):
            nominal_from_shape(self.solid, flip_faces=[0])

    def test_a_closed_solid_is_unaffected(self):
        nominal = demo_nominal()
        self.assertTrue(all(r["rule"] == "closed solid" and r["orientation"] == "outward"
                            for r in nominal.cad_faces))
        for mine, original in zip(nominal.faces, nominal.shape.Faces):
            self.assertTrue(mine.isSame(original))
            self.assertEqual(mine.Orientation, original.Orientation)


class TestRegisterOnOpenFaces(OpenFacesCase):
    def run_cli(self, *args):
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            status = cli.main(list(args))
        return status, out.getvalue(), err.getvalue()

    def test_register_reads_the_bump_outward_on_both_sides(self):
        """A band of +h across both sides of a scan of the open-face STEP (whose two faces'
        own normals disagree), in an unknown pose: the band reads +h on both sides."""
        reverse = (True, True)
        self.assertEqual(sorted(self.expected_orientations(reverse)), ["flipped", "outward"])
        faces, _ = _side_faces(reverse)
        cad = os.path.join(self.tmp, "register-sides.step")
        Part.makeCompound(faces).exportStep(cad)
        rng = np.random.default_rng(21)
        parts = [_surface_points(f, 1500, rng, margin=0.01) for f in self.truth_sides]
        p = np.concatenate([q for q, _ in parts])
        n = np.concatenate([m for _, m in parts])
        side = np.repeat([0, 1], [len(q) for q, _ in parts])
        band = (p[:, 2] > 0.35 * PARAMS.span) & (p[:, 2] < 0.5 * PARAMS.span)
        cad_points = p + np.where(band, BUMP_MM, 0.0)[:, None] * n
        pose = tf.make_transform(tf.rotation_from_vector(rng.normal(size=3)),
                                 rng.uniform(-50, 50, 3))
        points = os.path.join(self.tmp, "register-points.csv")
        np.savetxt(points, tf.apply_transform(pose, cad_points), delimiter=",",
                   header="x,y,z", comments="", fmt="%.6f")
        out = os.path.join(self.tmp, "register-out")
        status, stdout, stderr = self.run_cli("register", "--cad", cad, "--points", points,
                                              "--out", out)
        self.assertEqual(status, 0, stderr)
        with open(os.path.join(out, "result.json")) as fh:
            result = json.load(fh)
        self.assertEqual([r["orientation"] for r in result["cad_faces"]],
                         self.expected_orientations(reverse))
        deviation = np.loadtxt(os.path.join(out, "deviations.csv"), delimiter=",", skiprows=1,
                               usecols=3)
        for k in (0, 1):
            with self.subTest(side=k):
                np.testing.assert_allclose(deviation[band & (side == k)], BUMP_MM, atol=0.005)
                np.testing.assert_allclose(deviation[~band & (side == k)], 0.0, atol=0.005)

    def test_a_bad_flip_face_is_a_one_line_error(self):
        faces, _ = _side_faces()
        cad = os.path.join(self.tmp, "bad-flip.brep")
        Part.makeCompound(faces).exportBrep(cad)
        points = os.path.join(self.tmp, "bad-flip.csv")
        np.savetxt(points, self.on_side[0][0], delimiter=",", header="x,y,z", comments="")
        out = os.path.join(self.tmp, "bad-flip-out")
        status, _, stderr = self.run_cli("register", "--cad", cad, "--points", points,
                                         "--out", out, "--flip-face", "0,7")
        self.assertEqual(status, 2)
        self.assertEqual(stderr.strip().splitlines(),
                         ["bladeinspect: error: --flip-face 7: the CAD has 2 faces (0-1)"])
        self.assertFalse(os.path.exists(out))

    def test_report_and_inspect_take_the_option(self):
        parser = cli.build_parser()
        for command in (["report", "--cad", "c.step", "--points", "p.csv", "--out", "o"],
                        ["inspect", "--cad", "c.step", "--out", "o"]):
            args = parser.parse_args(command + ["--flip-face", "0,3"])
            self.assertEqual(args.flip_face, [0, 3])


if __name__ == "__main__":
    unittest.main()
