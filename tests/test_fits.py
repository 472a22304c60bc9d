"""Fit objectives (core.fits) against independent truths:

- locked degrees of freedom and region weights: point-to-point fits with known correspondences
  (each point's three coordinate planes as the surface, so sum d^2 = sum |x - q|^2) against
  Wahba's problem solved by SVD about the locked centre, the 2D Procrustes angle about one
  axis, the weighted mean translation and the weighted Kabsch solution; the covariance against
  a Monte Carlo of that closed form;
- minimax and fit to tolerance on an ellipsoid with a bump against a direct nonlinear
  minimisation (SLSQP on the epigraph, over the pose, with the exact distances) and on a plane
  against the closed-form optimum of the one free translation.
"""
import unittest

import numpy as np
from scipy.optimize import linprog, minimize

from BladeInspect.core import fits
from BladeInspect.core import transforms as tf
from BladeInspect.core.errors import InputError
from tests.helpers import demo_nominal
from tests.test_icp import ellipsoid_closest, surface_patch

UM = 1e-3   # mm


def coordinate_planes(targets):
    """closest_fn of the three planes x = q_x, y = q_y, z = q_z through each target: the
    cloud is the measured points repeated three times (see tripled)."""
    n = len(targets)
    normals = np.repeat(np.eye(3)[None], n, axis=0).transpose(1, 0, 2).reshape(3 * n, 3)
    anchors = np.tile(targets, (3, 1))

    def closest(points):
        d = np.sum((points - anchors) * normals, axis=1)
        return points - d[:, None] * normals, normals, d
    return closest


def tripled(points, values=None):
    return np.tile(points, (3, 1)) if values is None else np.tile(values, 3)


def wahba_about(p, q, w, c):
    """R minimising sum w |q - c - R (p - c)|^2 (Markley's SVD solution)."""
    B = ((q - c) * w[:, None]).T @ (p - c)
    U, _, Vt = np.linalg.svd(B)
    return U @ np.diag([1.0, 1.0, np.linalg.det(U) * np.linalg.det(Vt)]) @ Vt


def kabsch(p, q, w):
    """(R, t) minimising sum w |q - R p - t|^2."""
    cp, cq = w @ p / w.sum(), w @ q / w.sum()
    R = wahba_about(p - cp, q - cq, w, np.zeros(3))
    return R, cq - R @ cp


def rotation_log(R):
    angle = np.arccos(np.clip(0.5 * (np.trace(R) - 1.0), -1.0, 1.0))
    axis = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    return axis * (0.5 / np.sinc(angle / np.pi)) if angle > 0 else np.zeros(3)


def correspondences(rng, n=60, noise=0.05):
    p = rng.uniform(-30.0, 30.0, (n, 3)) * [1.0, 0.6, 0.3]
    axis = rng.normal(size=3)
    R = tf.rotation_from_vector(rng.uniform(0.0, 0.5) * axis / np.linalg.norm(axis))
    q = p @ R.T + rng.uniform(-5.0, 5.0, 3) + rng.normal(0.0, noise, (n, 3))
    return p, q, rng.uniform(0.5, 2.0, n)


class FreeAndZoneParsing(unittest.TestCase):
    def test_names_and_axes(self):
        free = fits.parse_free("tx, ty,rz")
        self.assertEqual(free.names, ("tx", "ty", "rz"))
        np.testing.assert_array_equal(free.basis, np.eye(6)[:, [0, 1, 5]])
        self.assertEqual(fits.parse_free("all").names, fits.DOF_NAMES)
        free = fits.parse_free("r_stacking,t_stacking", axes={"stacking": [0, 0, 2]})
        np.testing.assert_array_equal(free.basis[:, 0], [0, 0, 0, 0, 0, 1])
        np.testing.assert_array_equal(free.basis[:, 1], [0, 0, 1, 0, 0, 0])

    def test_bad_free(self):
        for text, fragment in (("tq", "unknown degree of freedom 'tq'"), ("tx,,ty", "empty"),
                               ("tx,tx", "twice"), ("rz,r_stacking", "not independent"),
                               ("r_engine", "unknown degree of freedom 'r_engine'"), ("", "empty")):
            with self.assertRaises(InputError) as cm:
                fits.parse_free(text, axes={"stacking": (0, 0, 1)})
            self.assertIn(fragment, str(cm.exception))
            self.assertTrue(str(cm.exception).startswith("--free: "))
        with self.assertRaises(InputError):
            fits.parse_free("r_bad", axes={"bad": (0, 0, 0)})

    def test_zone_weights(self):
        self.assertEqual(fits.parse_zone_weights("LE=2,TE=2,suction=1,pressure=0.5"),
                         {"LE": 2.0, "TE": 2.0, "suction": 1.0, "pressure": 0.5})
        zones = ("LE", "TE", "suction", "pressure")
        for text, fragment in (("LE2", "not zone=weight"), ("LE=x", "not a number"),
                               ("LE=-1", ">= 0"), ("LE=nan", ">= 0"), ("LE=1,LE=2", "twice"),
                               ("hub=1", "unknown zone 'hub'"), ("=1", "not zone=weight")):
            with self.assertRaises(InputError) as cm:
                fits.parse_zone_weights(text, zones)
            self.assertIn(fragment, str(cm.exception))
        np.testing.assert_array_equal(
            fits.per_zone(np.array(["LE", "", "TE", "suction"], dtype=object),
                                  {"LE": 2.0, "suction": 0.0}), [2.0, 1.0, 1.0, 0.0])


class LockedLeastSquares(unittest.TestCase):
    """Constrained least-squares optima in closed form, over random poses, noise and weights."""

    def fit(self, p, q, w, free, center, init=None, multipliers=None):
        init = np.eye(4) if init is None else init
        return fits.least_squares_fit(tripled(p), coordinate_planes(q), init, tripled(p, w),
                                      free=free, center=center,
                                      multipliers=None if multipliers is None
                                      else tripled(p, multipliers))

    def test_translations_locked_is_wahba_about_the_centre(self):
        rng = np.random.default_rng(11)
        for _ in range(10):
            p, q, w = correspondences(rng)
            c = rng.uniform(-10, 10, 3)
            result = self.fit(p, q, w, fits.parse_free("rx,ry,rz"), c)
            self.assertTrue(result.converged)
            np.testing.assert_allclose(result.transform[:3, :3], wahba_about(p, q, w, c),
                                       atol=1e-10)
            self.assertTrue(np.all(result.twist[:3] == 0.0))           # exactly locked
            np.testing.assert_allclose(tf.apply_transform(result.transform, c[None])[0], c,
                                       atol=1e-10)

    def test_rotation_about_a_named_axis_is_procrustes(self):
        rng = np.random.default_rng(12)
        for _ in range(10):
            p, q, w = correspondences(rng)
            axis = rng.normal(size=3)
            axis /= np.linalg.norm(axis)
            c = rng.uniform(-10, 10, 3)
            result = self.fit(p, q, w, fits.parse_free("r_engine", axes={"engine": axis}), c)
            u, v = p - c, q - c
            u_perp = u - np.outer(u @ axis, axis)
            angle = np.arctan2(w @ np.sum(v * np.cross(axis, u_perp), axis=1),
                               w @ np.sum(v * u_perp, axis=1))
            np.testing.assert_allclose(result.twist[3:], angle * axis, atol=1e-11)
            self.assertTrue(np.all(result.twist[:3] == 0.0))

    def test_two_rotations_free_is_the_constrained_optimum(self):
        """rz and the translations locked: the rotation vector (rx, ry, 0) about c minimising
        the exact objective, found by BFGS over those two components."""
        rng = np.random.default_rng(16)
        for _ in range(5):
            p, q, w = correspondences(rng)
            c = rng.uniform(-10, 10, 3)
            result = self.fit(p, q, w, fits.parse_free("rx,ry"), c)

            def cost(xy):
                R = tf.rotation_from_vector([xy[0], xy[1], 0.0])
                return w @ np.sum((q - c - (p - c) @ R.T) ** 2, axis=1)
            best = minimize(cost, np.zeros(2), method="BFGS", options={"gtol": 1e-10}).x
            np.testing.assert_allclose(result.twist[3:5], best, atol=1e-7)
            self.assertTrue(np.all(result.twist[[0, 1, 2, 5]] == 0.0))

    def test_in_plane_section_fit_is_2d_procrustes(self):
        """Points in a plane, targets moved in the plane and off it: the in-plane fit is the
        weighted 2D Kabsch solution and the points stay in their plane."""
        rng = np.random.default_rng(17)
        for _ in range(10):
            frame = tf.random_rotation(rng)
            u, v, normal = frame.T
            uv = rng.uniform(-30.0, 30.0, (50, 2)) * [1.0, 0.2]
            p = uv @ np.vstack([u, v]) + 7.0 * normal
            angle = rng.uniform(-0.3, 0.3)
            rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
            quv = uv @ rot.T + rng.uniform(-2, 2, 2) + rng.normal(0.0, 0.01, (50, 2))
            q = quv @ np.vstack([u, v]) + (7.0 + rng.normal(0.0, 0.05, 50))[:, None] * normal
            w = rng.uniform(0.5, 2.0, 50)
            result = self.fit(p, q, w, fits.in_plane_free(normal, u + 0.3 * normal), None)
            R2, t2 = kabsch(np.c_[uv, np.zeros(50)], np.c_[quv, np.zeros(50)], w)
            moved = tf.apply_transform(result.transform, p)
            expected = (np.c_[uv, np.zeros(50)] @ R2.T + t2)[:, :2]
            np.testing.assert_allclose(moved @ np.vstack([u, v]).T, expected, atol=1e-9)
            np.testing.assert_allclose(moved @ normal, 7.0, atol=1e-9)

    def test_rotations_locked_is_the_weighted_mean_shift(self):
        rng = np.random.default_rng(13)
        for _ in range(10):
            p, q, w = correspondences(rng)
            init = tf.random_transform(rng, 3.0)
            start = tf.apply_transform(init, p)
            result = self.fit(p, q, w, fits.parse_free("tx,ty,tz"), None, init)
            np.testing.assert_allclose(result.twist[:3], w @ (q - start) / w.sum(), atol=1e-11)
            self.assertTrue(np.all(result.twist[3:] == 0.0))
            np.testing.assert_array_equal(result.transform[:3, :3], init[:3, :3])

    def test_region_weights_multiply_the_weights(self):
        rng = np.random.default_rng(14)
        for _ in range(10):
            p, q, w = correspondences(rng)
            zone = rng.choice(np.array(["LE", "TE", "suction", "pressure"], dtype=object),
                              len(p))
            z = fits.per_zone(zone, fits.parse_zone_weights("LE=3,TE=2,suction=0.5"))
            result = self.fit(p, q, w, None, None, multipliers=z)
            R, t = kabsch(p, q, w * z)
            np.testing.assert_allclose(result.transform[:3, :3], R, atol=1e-10)
            np.testing.assert_allclose(result.transform[:3, 3], t, atol=1e-9)

    def test_covariance_matches_monte_carlo_of_the_closed_form(self):
        """Noise of variance sigma^2 / w (w the noise model's weights), zone multipliers z on
        top: the stated covariance of the rotation-locked and the free fits against the
        scatter of the closed-form solutions."""
        rng = np.random.default_rng(15)
        n, sigma = 80, 0.02
        p = rng.uniform(-30.0, 30.0, (n, 3)) * [1.0, 0.6, 0.3]
        w = rng.uniform(0.5, 2.0, n)
        z = rng.choice([1.0, 10.0], n)
        c = w @ p / w.sum()
        draws = []
        for _ in range(400):
            q = p + rng.normal(0.0, 1.0, (n, 3)) * (sigma / np.sqrt(w))[:, None]
            R, t = kabsch(p, q, w * z)
            draws.append(np.r_[t + R @ c - c, rotation_log(R)])
        truth = np.cov(np.array(draws).T)
        q = p + rng.normal(0.0, 1.0, (n, 3)) * (sigma / np.sqrt(w))[:, None]
        stated = self.fit(p, q, w, None, c, multipliers=z).covariance
        # 400 draws: a variance is known to ~7 %; s^2 from one cloud of 240 residuals to ~9 %.
        np.testing.assert_allclose(np.diag(stated), np.diag(truth), rtol=0.3)
        naive = fits.least_squares_fit(tripled(p), coordinate_planes(q), np.eye(4),
                                       tripled(p, w * z), center=c).covariance
        # The weights w z are not the noise model's: treating them as if they were is wrong.
        self.assertGreater(np.max(np.abs(np.diag(naive) / np.diag(truth) - 1.0)), 0.3)


def exact_epigraph(start, distance, lower, upper, free_rows, center):
    """Independent max-min slack: SLSQP on (theta, m), maximise m subject to
    d_i(theta) - l_i >= m and u_i - d_i(theta) >= m, with the exact distances of the start
    points moved by x -> c + R(w)(x - c) + t (theta: the free components of (t, 30 w))."""
    k = len(free_rows)

    def moved(theta):
        xi = np.zeros(6)
        xi[free_rows] = theta
        xi[3:] /= 30.0
        R = tf.rotation_from_vector(xi[3:])
        return center + (start - center) @ R.T + xi[:3]

    def constraints(x):
        d = distance(moved(x[:k]))
        return np.concatenate([d - lower - x[k], upper - d - x[k]])

    x0 = np.zeros(k + 1)
    x0[k] = np.min(constraints(x0))
    res = minimize(lambda x: -x[k], x0, jac=lambda x: -np.eye(k + 1)[k], method="SLSQP",
                   constraints=[{"type": "ineq", "fun": constraints}],
                   options={"ftol": 1e-14, "maxiter": 500})
    return float(np.min(constraints(np.r_[res.x[:k], 0.0])))


def iterated_lp_minimax(start, closest_fn, center, iterations=30, tol_mm=1e-10):
    """Independent minimax: the full linear programme (every point, interior point method) of
    the point-to-plane linearisation about the current pose, the step composed on the left
    as a rotation vector about the centre, iterated until the step vanishes. Returns the
    exact max |d| at the last pose."""
    moved = start.copy()
    radius = np.max(np.linalg.norm(start - center, axis=1))
    for _ in range(iterations):
        _, normals, d = closest_fn(moved)
        J = np.hstack([normals, np.cross(moved - center, normals) * (1.0 / radius)])
        ones = np.ones((len(d), 1))
        res = linprog(np.r_[np.zeros(6), 1.0],
                      A_ub=np.vstack([np.hstack([J, -ones]), np.hstack([-J, -ones])]),
                      b_ub=np.r_[-d, d], bounds=[(None, None)] * 6 + [(0, None)],
                      method="highs-ipm")
        step = res.x[:6] / np.r_[1.0, 1.0, 1.0, radius, radius, radius]
        R = tf.rotation_from_vector(step[3:])
        moved = center + (moved - center) @ R.T + step[:3]
        if np.abs(res.x[:6]).max() < tol_mm:
            break
    return float(np.max(np.abs(closest_fn(moved)[2])))


def ellipsoid_distance(points):
    return ellipsoid_closest(points)[2]


def bumped_ellipsoid(rng, n, bump_mm, noise_mm):
    """(measured points, pose near the truth): an ellipsoid patch with a bump on one side."""
    q = surface_patch(rng, n)
    _, normals, _ = ellipsoid_closest(q)
    top = q[np.argmax(q[:, 2])]
    bump = bump_mm * np.exp(-np.sum((q - top) ** 2, axis=1) / (2.0 * 6.0 ** 2))
    cad = q + (bump + rng.normal(0.0, noise_mm, n))[:, None] * normals
    truth = tf.random_transform(rng, 20.0)
    measured = tf.apply_transform(tf.invert_transform(truth), cad)
    return measured, truth


class ChebyshevFits(unittest.TestCase):
    """Minimax and tolerance fits on an exact ellipsoid against a direct nonlinear solution,
    over random poses and noise, starting from the least-squares fit."""

    def least_squares(self, measured, truth, rng):
        init = tf.make_transform(tf.rotation_from_vector(rng.normal(0, 1e-3, 3)),
                                 rng.normal(0, 0.05, 3)) @ truth
        return fits.least_squares_fit(measured, ellipsoid_closest, init,
                                      np.ones(len(measured)))

    def test_minimax_against_direct_minimisation(self):
        rng = np.random.default_rng(21)
        for free_text in ("all", "all", "tx,ty,rz"):
            measured, truth = bumped_ellipsoid(rng, 300, rng.uniform(0.01, 0.05), 0.002)
            ls = self.least_squares(measured, truth, rng)
            free = fits.parse_free(free_text)
            mm = fits.minimax_fit(measured, ellipsoid_closest, ls.transform, ls.inlier * 1.0,
                                  free=free)
            self.assertTrue(mm.converged)
            start = tf.apply_transform(ls.transform, measured)
            rows = [fits.DOF_NAMES.index(name) for name in free.names]
            best = -exact_epigraph(start, ellipsoid_distance, 0.0, 0.0, rows, mm.center)
            self.assertLess(abs(mm.max_abs_deviation - best), 0.5 * UM)
            self.assertLessEqual(mm.max_abs_deviation, ls.max_abs_deviation + 1e-12)
            exact = ellipsoid_distance(tf.apply_transform(mm.transform, measured))
            self.assertAlmostEqual(np.max(np.abs(exact)), mm.max_abs_deviation, delta=1e-12)
            locked = [i for i in range(6) if i not in rows]
            self.assertTrue(np.all(mm.twist[locked] == 0.0))

    def test_known_start_saves_an_evaluation(self):
        rng = np.random.default_rng(23)
        measured, truth = bumped_ellipsoid(rng, 300, 0.03, 0.002)
        ls = self.least_squares(measured, truth, rng)
        calls = []

        def counted(points):
            calls.append(len(points))
            return ellipsoid_closest(points)
        _, normals, distances = ellipsoid_closest(tf.apply_transform(ls.transform, measured))
        w = np.ones(len(measured))
        for fit in (fits.least_squares_fit, fits.minimax_fit):
            plain = fit(measured, counted, ls.transform, w)
            n_plain = len(calls)
            known = fit(measured, counted, ls.transform, w, at_init=(distances, normals))
            self.assertEqual(len(calls) - n_plain, n_plain - 1)
            self.assertEqual(known.iterations, plain.iterations - 1)
            np.testing.assert_allclose(known.transform, plain.transform, atol=1e-12)
            del calls[:]
        with self.assertRaises(InputError):
            fits.minimax_fit(measured, counted, ls.transform, w, at_init=(distances[1:], normals))

    def test_tolerance_fit_passes_where_least_squares_fails(self):
        rng = np.random.default_rng(22)
        for _ in range(3):
            measured, truth = bumped_ellipsoid(rng, 300, 0.04, 0.001)
            ls = self.least_squares(measured, truth, rng)
            start = tf.apply_transform(ls.transform, measured)
            minimax = -exact_epigraph(start, ellipsoid_distance, 0.0, 0.0, list(range(6)),
                                      ls.center)
            # A zone that the least-squares pose fails but the best pose fits.
            T = 0.5 * (minimax + ls.max_abs_deviation)
            fit = fits.tolerance_fit(measured, ellipsoid_closest, ls.transform,
                                     np.ones(len(measured)), -T, T)
            self.assertTrue(fit.fits)
            self.assertGreater(fit.margin, 0.0)
            self.assertEqual(fit.violation, 0.0)
            self.assertLess(abs(fit.margin - (T - minimax)), 0.5 * UM)
            self.assertLessEqual(fit.max_abs_deviation, T)

            # Asymmetric per-point zones no pose fits: the least largest violation.
            lower = np.full(len(measured), -0.2 * minimax)
            upper = np.where(measured[:, 0] > np.median(measured[:, 0]), 0.5, 0.6) * minimax
            fit = fits.tolerance_fit(measured, ellipsoid_closest, ls.transform,
                                     np.ones(len(measured)), lower, upper)
            best = exact_epigraph(start, ellipsoid_distance, lower, upper, list(range(6)),
                                  fit.center)
            self.assertFalse(fit.fits)
            self.assertGreater(fit.violation, 0.0)
            self.assertLess(abs(fit.margin - best), 0.5 * UM)

            # The same with only tx, ty, rz free.
            free = fits.parse_free("tx,ty,rz")
            fit = fits.tolerance_fit(measured, ellipsoid_closest, ls.transform,
                                     np.ones(len(measured)), lower, upper, free=free)
            best = exact_epigraph(start, ellipsoid_distance, lower, upper, [0, 1, 5],
                                  fit.center)
            self.assertLess(abs(fit.margin - best), 0.5 * UM)
            self.assertTrue(np.all(fit.twist[[2, 3, 4]] == 0.0))


class DemoBlade(unittest.TestCase):
    """The demo blade's exact CAD distance (OCC-backed), a scan-like cloud on its suction and
    pressure faces with a bump on the suction side: minimax against the test's own iterated
    linear programme."""

    def test_minimax_on_the_demo_blade(self):
        from BladeInspect.inspection.closest_fn import exact_closest_fn
        nominal = demo_nominal()
        closest = exact_closest_fn(nominal)
        rng = np.random.default_rng(41)
        faces = nominal.roles["suction"] + nominal.roles["pressure"]
        on_sides = np.flatnonzero(np.isin(nominal.samples.face, faces))
        idx = rng.choice(on_sides, 3000, replace=False)
        q, normals = nominal.samples.xyz[idx], nominal.samples.normal[idx]
        suction = np.isin(nominal.samples.face[idx], nominal.roles["suction"])
        top = q[suction][np.argmax(q[suction][:, 2])] * [1.0, 1.0, 0.5]
        bump = 0.03 * np.exp(-np.sum((q - top) ** 2, axis=1) / (2.0 * 8.0 ** 2)) * suction
        cad = q + (bump + rng.normal(0.0, 0.002, len(q)))[:, None] * normals
        truth = tf.random_transform(rng, 10.0)
        measured = tf.apply_transform(tf.invert_transform(truth), cad)
        init = tf.make_transform(tf.rotation_from_vector(rng.normal(0, 2e-4, 3)),
                                 rng.normal(0, 0.01, 3)) @ truth
        w = np.ones(len(measured))
        ls = fits.least_squares_fit(measured, closest, init, w)
        mm = fits.minimax_fit(measured, closest, ls.transform, w)
        self.assertTrue(ls.converged and mm.converged)
        self.assertLess(mm.max_abs_deviation, ls.max_abs_deviation)
        start = tf.apply_transform(ls.transform, measured)
        best = iterated_lp_minimax(start, closest, mm.center)
        self.assertLess(abs(mm.max_abs_deviation - best), 0.5 * UM)


class PlaneCases(unittest.TestCase):
    """A plane with only the translation along its normal free: closed-form optima."""

    @staticmethod
    def plane(points):
        normals = np.tile([0.0, 0.0, 1.0], (len(points), 1))
        return points * [1.0, 1.0, 0.0], normals, points[:, 2].copy()

    def test_one_sided_bump(self):
        rng = np.random.default_rng(31)
        for _ in range(20):
            n = 400
            xy = rng.uniform(-20.0, 20.0, (n, 2))
            h = rng.uniform(0.02, 0.1)
            z = rng.normal(0.0, 0.002, n) + h * (np.hypot(xy[:, 0] - 15, xy[:, 1]) < 4.0)
            points = np.column_stack([xy, z])
            free = fits.parse_free("tz")
            w = np.ones(n)
            ls = fits.least_squares_fit(points, self.plane, np.eye(4), w, free=free)
            self.assertAlmostEqual(ls.twist[2], -z.mean(), delta=1e-12)
            half_range = 0.5 * (z.max() - z.min())
            T = 0.5 * (half_range + ls.max_abs_deviation)   # fails under least squares
            self.assertGreater(ls.max_abs_deviation, T)
            fit = fits.tolerance_fit(points, self.plane, np.eye(4), w, -T, T, free=free)
            self.assertTrue(fit.fits)
            self.assertAlmostEqual(fit.margin, T - half_range, delta=1e-9)
            mm = fits.minimax_fit(points, self.plane, np.eye(4), w, free=free)
            self.assertAlmostEqual(mm.max_abs_deviation, half_range, delta=1e-9)
            self.assertAlmostEqual(mm.twist[2], -0.5 * (z.max() + z.min()), delta=1e-9)
            self.assertTrue(np.all(mm.twist[[0, 1, 3, 4, 5]] == 0.0))
            # Random per-point zones: margin(tz) = min(tz + min(z - l), min(u - z) - tz).
            lower = -rng.uniform(0.0, 0.05, n)
            upper = rng.uniform(0.0, 0.05, n)
            fit = fits.tolerance_fit(points, self.plane, np.eye(4), w, lower, upper, free=free)
            a, b = np.min(z - lower), np.min(upper - z)
            self.assertAlmostEqual(fit.margin, 0.5 * (a + b), delta=1e-9)
            self.assertAlmostEqual(fit.twist[2], 0.5 * (b - a), delta=1e-9)
            self.assertEqual(fit.fits, a + b >= 0)

    def test_minimax_leaves_what_the_plane_does_not_fix(self):
        """All six free on a plane: the flatness zone over tz, rx, ry (against SLSQP on the
        exact distance), and tx, ty, rz, which no point constrains, left at 0."""
        rng = np.random.default_rng(32)
        for _ in range(5):
            xy = rng.uniform(-20.0, 20.0, (300, 2))
            z = rng.normal(0.0, 0.002, 300) + 0.05 * (np.hypot(xy[:, 0] - 15, xy[:, 1]) < 4.0)
            points = np.column_stack([xy, z + 1e-3 * xy[:, 0]])
            mm = fits.minimax_fit(points, self.plane, np.eye(4), np.ones(300))
            self.assertTrue(mm.converged)
            self.assertTrue(np.all(np.abs(mm.twist[[0, 1, 5]]) < 1e-12))
            best = -exact_epigraph(points, lambda x: x[:, 2], 0.0, 0.0, [2, 3, 4], mm.center)
            self.assertLess(abs(mm.max_abs_deviation - best), 0.5 * UM)

    def test_a_wrong_gradient_is_not_reported_as_converged(self):
        """Normals opposite to the distance's gradient: every predicted gain is a loss; the
        fit keeps the start and says it did not converge."""
        rng = np.random.default_rng(34)
        points = np.column_stack([rng.uniform(-5, 5, (50, 2)), rng.normal(0.01, 0.01, 50)])

        def wrong(p):
            closest, normals, d = self.plane(p)
            return closest, -normals, d
        mm = fits.minimax_fit(points, wrong, np.eye(4), np.ones(50), free=fits.parse_free("tz"))
        self.assertFalse(mm.converged)
        self.assertAlmostEqual(mm.max_abs_deviation, np.max(np.abs(points[:, 2])), delta=1e-15)

    def test_dispatch_and_json(self):
        import json
        rng = np.random.default_rng(33)
        points = np.column_stack([rng.uniform(-5, 5, (50, 2)), rng.normal(0, 0.01, 50)])
        w = np.ones(50)
        free = fits.parse_free("tz,rx,ry")
        direct = fits.tolerance_fit(points, self.plane, np.eye(4), w, -0.02, 0.03, free=free)
        named = fits.fit("tolerance", points, self.plane, np.eye(4), w, free=free,
                         lower=-0.02, upper=0.03)
        np.testing.assert_array_equal(direct.transform, named.transform)
        record = json.loads(json.dumps(named.to_json(), allow_nan=False))
        self.assertEqual(record["free"], ["tz", "rx", "ry"])
        self.assertEqual(record["fits"], named.fits)
        self.assertEqual(record["covariance"][0][0], 0.0)     # tx locked
        for kwargs, fragment in ((dict(objective="chebyshev"), "unknown objective"),
                                 (dict(objective="minimax", multipliers=w), "least-squares"),
                                 (dict(objective="tolerance"), "needed"),
                                 (dict(objective="minimax", lower=0, upper=1), "only")):
            with self.assertRaises(InputError) as cm:
                fits.fit(points=points, closest_fn=self.plane, init=np.eye(4), weights=w,
                         **kwargs)
            self.assertIn(fragment, str(cm.exception))

    def test_bad_input(self):
        points = np.zeros((10, 3))
        with self.assertRaises(InputError):
            fits.tolerance_fit(points, self.plane, np.eye(4), np.ones(10), 0.1, -0.1)
        with self.assertRaises(InputError):
            fits.tolerance_fit(points, self.plane, np.eye(4), np.ones(10), -np.inf, 0.1)
        with self.assertRaises(InputError):
            fits.minimax_fit(points, self.plane, np.eye(4), -np.ones(10))
        with self.assertRaises(InputError):
            fits.minimax_fit(points, self.plane, np.eye(4), np.r_[np.ones(3), np.zeros(7)],
                             free=fits.parse_free("all"))


if __name__ == "__main__":
    unittest.main()
