"""ICP against an analytic surface (a triaxial ellipsoid patch, exact closest points by a
safeguarded Newton iteration written here), judged against the known transform that moved the
points, Monte-Carlo scatter, Kabsch's SVD solution and the exact objective's stationarity."""
import unittest

import numpy as np

from BladeInspect.core import icp
from BladeInspect.core import transforms as tf
from BladeInspect.core.errors import InputError

AXES = np.array([35.0, 20.0, 8.0])   # blade-sized, three distinct axes: the pose is determined
CORNERS = np.array([[x, y, z] for x in (-35.0, 35.0) for y in (-20.0, 20.0)
                    for z in (-8.0, 8.0)])


def ellipsoid_closest(points, axes=AXES):
    """Exact closest point on the ellipsoid sum (x_i / a_i)^2 = 1.

    The closest point is q_i = a_i^2 p_i / (a_i^2 + t) with t the root, above -min a^2, of the
    decreasing F(t) = sum (a_i p_i / (a_i^2 + t))^2 - 1; then p - q = t q / a^2, so the signed
    distance is t |q / a^2| (t > 0 outside). Newton, falling back to bisection in a bracket.
    """
    a2 = axes ** 2
    lo = np.full(len(points), -a2.min())
    hi = axes.max() * np.linalg.norm(points, axis=1) + 1.0
    t = np.zeros(len(points))
    for _ in range(200):
        den = a2 + t[:, None]
        F = np.sum((axes * points / den) ** 2, axis=1) - 1.0
        dF = -2.0 * np.sum((axes * points) ** 2 / den ** 3, axis=1)
        lo = np.where(F > 0, t, lo)
        hi = np.where(F <= 0, t, hi)
        t_new = t - F / dF
        outside = ~((t_new >= lo) & (t_new <= hi))
        t_new[outside] = 0.5 * (lo[outside] + hi[outside])
        # Newton converges quadratically: a step this small leaves an error far below it.
        done = np.all(np.abs(t_new - t) <= 1e-12 * (1.0 + np.abs(t)))
        t = t_new
        if done:
            break
    q = a2 * points / (a2 + t[:, None])
    grad = q / a2
    gnorm = np.linalg.norm(grad, axis=1)
    return q, grad / gnorm[:, None], t * gnorm


def surface_patch(rng, n):
    """Points on the ellipsoid over an asymmetric patch (as one scan would see it)."""
    out = []
    while sum(len(o) for o in out) < n:
        u = rng.normal(size=(4 * n, 3))
        u /= np.linalg.norm(u, axis=1)[:, None]
        p = u * AXES
        out.append(p[(p[:, 0] > -20.0) & (p[:, 2] > -4.0) & (p[:, 1] < 15.0)])
    return np.concatenate(out)[:n]


def measured_cloud(rng, n, noise):
    """(measured points, truth measured->CAD, CAD points, normals): surface points pushed along
    their normal by `noise` (an (n,) array of offsets), moved into a random frame."""
    cad = surface_patch(rng, n)
    _, normals, _ = ellipsoid_closest(cad)
    noisy = cad + noise[:, None] * normals
    truth = tf.random_transform(rng, 100.0)
    return tf.apply_transform(tf.invert_transform(truth), noisy), truth, cad, normals


def start_near(rng, truth, angle_deg=3.0, shift_mm=2.0):
    axis = rng.normal(size=3)
    R = tf.rotation_from_vector(axis / np.linalg.norm(axis) * np.radians(angle_deg))
    d = rng.normal(size=3)
    return tf.make_transform(R, d / np.linalg.norm(d) * shift_mm) @ truth


def pose_error(T_est, truth):
    return tf.corner_displacement(T_est @ tf.invert_transform(truth), np.eye(4), CORNERS)


class TestEllipsoidHelper(unittest.TestCase):
    def test_closest_points_are_exact(self):
        rng = np.random.default_rng(0)
        p = surface_patch(rng, 500) + rng.normal(size=(500, 3)) * 2.0
        q, n, d = ellipsoid_closest(p)
        np.testing.assert_allclose(np.sum((q / AXES) ** 2, axis=1), 1.0, atol=1e-13)
        np.testing.assert_allclose(p - q, d[:, None] * n, atol=1e-11)
        inside = np.sum((p / AXES) ** 2, axis=1) < 1
        np.testing.assert_array_equal(d < 0, inside)
        # No surface point is nearer than q (dense sampling of the whole ellipsoid).
        u = rng.normal(size=(200000, 3))
        dense = u / np.linalg.norm(u, axis=1)[:, None] * AXES
        for i in range(0, 500, 50):
            self.assertLessEqual(abs(d[i]), np.min(np.linalg.norm(dense - p[i], axis=1)) + 1e-12)


class TestHorn(unittest.TestCase):
    def test_exact_recovery_and_agreement_with_kabsch(self):
        rng = np.random.default_rng(1)
        for _ in range(20):
            src = rng.normal(size=(50, 3)) * [30, 10, 3]
            T = tf.random_transform(rng, 100.0)
            tgt = tf.apply_transform(T, src)
            R, t = icp.horn(tgt, src, rng.uniform(0.1, 2.0, 50))
            np.testing.assert_allclose(tf.make_transform(R, t), T, atol=1e-10)
            # With noise: Horn's quaternion solution equals the weighted SVD (Kabsch/Umeyama).
            noisy = tgt + rng.normal(size=tgt.shape) * 0.5
            w = rng.uniform(0.1, 2.0, 50)
            R, t = icp.horn(noisy, src, w)
            cs, ct = w @ src / w.sum(), w @ noisy / w.sum()
            U, _, Vt = np.linalg.svd(((noisy - ct) * w[:, None]).T @ (src - cs))
            D = np.diag([1.0, 1.0, np.linalg.det(U @ Vt)])
            R_ref = U @ D @ Vt
            np.testing.assert_allclose(R, R_ref, atol=1e-10)
            np.testing.assert_allclose(t, ct - R_ref @ cs, atol=1e-9)


class TestPoseUncertainty(unittest.TestCase):
    def test_closed_forms(self):
        center = np.array([1.0, 2.0, 3.0])
        corners = CORNERS
        cov = np.zeros((6, 6))
        cov[:3, :3] = np.eye(3) * 0.002 ** 2
        self.assertAlmostEqual(icp.pose_uncertainty(cov, center, corners),
                               np.sqrt(3) * 0.002, places=12)
        cov = np.zeros((6, 6))
        cov[5, 5] = 1e-5 ** 2   # rotation about z only: a corner moves by angle * radius in xy
        radius = np.max(np.hypot(corners[:, 0] - 1.0, corners[:, 1] - 2.0))
        self.assertAlmostEqual(icp.pose_uncertainty(cov, center, corners), 1e-5 * radius,
                               places=12)


class TestICP(unittest.TestCase):
    def test_noise_free_recovers_the_transform(self):
        rng = np.random.default_rng(2)
        for trial in range(5):
            pts, truth, _, _ = measured_cloud(rng, 400, np.zeros(400))
            res = icp.icp(pts, None, ellipsoid_closest, start_near(rng, truth))
            self.assertTrue(res.converged)
            self.assertLess(pose_error(res.transform, truth), 1e-6, "trial %d" % trial)
            self.assertLess(np.max(np.abs(res.distances)), 1e-6)
            self.assertTrue(res.inlier.all())

    def test_robust_weights_take_in_residuals_offset_to_one_side(self):
        # From a rough start every residual may be about +1.5 mm: the scale must take them
        # in, not reject them all as far from their common median.
        rng = np.random.default_rng(10)
        d = 1.5 + rng.uniform(-0.2, 0.2, 1000)
        rho, scale = icp.robust_weights(d, np.ones(1000), icp.ICPOptions())
        self.assertTrue(np.all(rho > 0.5))
        self.assertGreaterEqual(np.mean(rho == 1.0), 0.5)
        self.assertAlmostEqual(scale, np.median(d) / 3.0)   # half the points within k_full
        # At convergence, a few gross errors among 6 um noise get no weight, the rest full.
        d = rng.uniform(-0.006, 0.006, 1000)
        d[:20] = rng.uniform(0.1, 0.5, 20)
        rho, _ = icp.robust_weights(d, np.ones(1000), icp.ICPOptions())
        np.testing.assert_array_equal(rho[:20], 0.0)
        np.testing.assert_array_equal(rho[20:], 1.0)

    def test_scatter_agrees_with_the_predicted_uncertainty(self):
        rng = np.random.default_rng(3)
        errors, predicted = [], []
        for _ in range(40):
            noise = rng.uniform(-0.006, 0.006, 300)
            pts, truth, _, _ = measured_cloud(rng, 300, noise)
            res = icp.icp(pts, None, ellipsoid_closest, start_near(rng, truth))
            self.assertTrue(res.converged)
            delta = res.transform @ tf.invert_transform(truth)
            errors.append(tf.apply_transform(delta, CORNERS) - CORNERS)
            predicted.append(icp.pose_uncertainty(res.covariance, res.center, CORNERS))
            # Residual scale: the noise's RMS (0.006 / sqrt 3), residuals = noise + fit.
            self.assertAlmostEqual(res.sigma0, 0.006 / np.sqrt(3), delta=0.0006)
        errors = np.array(errors)                       # (trials, 8 corners, 3)
        worst_rms = np.max(np.sqrt(np.mean(np.sum(errors ** 2, axis=2), axis=0)))
        self.assertLess(abs(worst_rms / np.mean(predicted) - 1.0), 0.3,
                        "scatter %.3g mm vs predicted %.3g mm" % (worst_rms, np.mean(predicted)))

    def test_outliers_and_defect_do_not_move_the_pose(self):
        rng = np.random.default_rng(4)
        n = 1000
        shifts, flank_kept, flank_total = [], 0, 0
        for trial in range(3):
            clean = rng.uniform(-0.006, 0.006, n)
            cad = surface_patch(rng, n)
            # A smooth 0.05 mm raised defect over the 5% of points nearest to a random one.
            to_centre = np.linalg.norm(cad - cad[rng.integers(n)], axis=1)
            bump = np.argsort(to_centre)[:n // 20]
            radius = to_centre[bump].max() * (1 + 1e-9)
            height = 0.05 * np.cos(0.5 * np.pi * to_centre[bump] / radius) ** 2
            others = np.setdiff1d(np.arange(n), bump)
            gross = rng.choice(others, size=n // 50, replace=False)
            clean[gross] += rng.choice([-1.0, 1.0], size=len(gross)) * rng.uniform(0.1, 0.5,
                                                                                   len(gross))
            bumped = clean.copy()
            bumped[bump] += height
            _, normals, _ = ellipsoid_closest(cad)
            truth = tf.random_transform(rng, 100.0)
            # Gross errors come with a poor signal (SNR 2-10 against 60-95): their low weight
            # must not excuse them from being flagged.
            snr = rng.uniform(60.0, 95.0, n)
            snr[gross] = rng.uniform(2.0, 10.0, len(gross))
            init = start_near(rng, truth)
            fits = []
            for noise in (clean, bumped):
                pts = tf.apply_transform(tf.invert_transform(truth),
                                         cad + noise[:, None] * normals)
                fits.append(icp.icp(pts, snr, ellipsoid_closest, init))
            res = fits[1]
            self.assertTrue(res.converged)
            bound = icp.pose_uncertainty(res.covariance, res.center, CORNERS)
            self.assertLess(pose_error(res.transform, truth), 3 * bound, "trial %d" % trial)
            for fit in fits:
                self.assertFalse(fit.inlier[gross].any())
            self.assertFalse(res.inlier[bump[height > 0.03]].any())
            shifts.append(pose_error(res.transform, fits[0].transform) / bound)
            flank = bump[(height > 0.01) & (height < 0.03)]
            flank_kept += np.count_nonzero(res.inlier[flank])
            flank_total += len(flank)
            # Good points keep their weight, but for a margin along the defect's rim, where
            # most of a point's neighbourhood is on the defect.
            good = np.setdiff1d(others, gross)
            gaps = np.linalg.norm(cad[:, None] - cad[None, :], axis=2)
            rim = np.median(np.sort(gaps, axis=1)[:, 16])    # a neighbourhood's radius
            far = good[np.min(gaps[np.ix_(good, bump)], axis=1) > rim]
            self.assertGreater(len(far), 0.8 * n)
            self.assertGreater(np.mean(res.inlier[far]), 0.99)
            self.assertGreater(np.mean(res.inlier[good]), 0.95)
            self.assertAlmostEqual(res.rms, 0.006 / np.sqrt(3), delta=0.0005)
        # The flanks (10-30 um: 2-7 sigma) pass the per-point test in good part and would
        # tilt the fit by about its 1-sigma bound; the neighbourhood test rejects them.
        self.assertLess(flank_kept / flank_total, 0.25)
        self.assertLess(np.mean(shifts), 0.8)

    def test_snr_weights_beat_equal_weights_on_heteroscedastic_noise(self):
        rng = np.random.default_rng(5)
        weighted, unweighted, predicted = [], [], []
        for _ in range(20):
            n = 500
            snr = rng.uniform(2.0, 100.0, n)
            noise = rng.normal(size=n) * 0.002 * np.sqrt(100.0 / snr)   # sigma^2 ~ 1/SNR
            pts, truth, _, _ = measured_cloud(rng, n, noise)
            init = start_near(rng, truth)
            res_w = icp.icp(pts, snr, ellipsoid_closest, init)
            res_u = icp.icp(pts, None, ellipsoid_closest, init)
            weighted.append(pose_error(res_w.transform, truth))
            unweighted.append(pose_error(res_u.transform, truth))
            predicted.append(icp.pose_uncertainty(res_w.covariance, res_w.center, CORNERS))
        rms_w = np.sqrt(np.mean(np.square(weighted)))
        rms_u = np.sqrt(np.mean(np.square(unweighted)))
        self.assertLess(rms_w, 0.8 * rms_u, "weighted %.3g vs unweighted %.3g" % (rms_w, rms_u))
        self.assertLess(max(np.array(weighted) / np.array(predicted)), 3.0)

    def test_result_is_a_stationary_point_of_the_exact_objective(self):
        rng = np.random.default_rng(6)
        snr = rng.uniform(10.0, 100.0, 400)
        noise = rng.normal(size=400) * 0.004 * np.sqrt(50.0 / snr)
        pts, truth, _, _ = measured_cloud(rng, 400, noise)
        start = start_near(rng, truth, 5.0, 3.0)
        # Run to the step tolerances, not stopped by the pose's uncertainty.
        res = icp.icp(pts, snr, ellipsoid_closest, start, icp.ICPOptions(uncertainty_fraction=0))
        self.assertTrue(res.converged)
        # By default it stops once what is left is under 1 % of the pose's own 1 sigma.
        early = icp.icp(pts, snr, ellipsoid_closest, start)
        self.assertTrue(early.converged)
        self.assertLess(early.iterations, res.iterations)
        sigma = icp.pose_uncertainty(res.covariance, res.center, CORNERS)
        self.assertLess(pose_error(early.transform, res.transform), 0.02 * sigma)
        # The distances reported are the exact ones at the returned pose.
        moved = tf.apply_transform(res.transform, pts)
        np.testing.assert_allclose(res.distances, ellipsoid_closest(moved)[2], atol=1e-9)

        def objective(motion):
            T = tf.make_transform(tf.rotation_from_vector(motion[3:]),
                                  motion[:3]) @ res.transform
            d = ellipsoid_closest(tf.apply_transform(T, pts))[2]
            return np.sum(res.weights * d ** 2)
        f0 = objective(np.zeros(6))
        for k in range(6):
            h = 1e-4 if k < 3 else 1e-6
            e = np.zeros(6)
            e[k] = h
            fp, fm = objective(e), objective(-e)
            self.assertGreater(fp, f0)
            self.assertGreater(fm, f0)
            vertex = h * (fm - fp) / (2 * (fp - 2 * f0 + fm))
            self.assertLess(abs(vertex), 1e-7 if k < 3 else 1e-9, "direction %d" % k)

    def test_points_without_signal_or_distance_are_left_out(self):
        rng = np.random.default_rng(8)
        pts, truth, _, _ = measured_cloud(rng, 400, rng.uniform(-0.006, 0.006, 400))
        snr = rng.uniform(50.0, 100.0, 400)
        snr[:20] = 0.0
        missing = np.zeros(400, bool)
        missing[20:40] = True

        def closest_with_misses(p):
            # e.g. a ray-cast distance that found no face: NaN everywhere for those points
            q, n, d = ellipsoid_closest(p)
            q[missing], n[missing], d[missing] = np.nan, np.nan, np.nan
            return q, n, d
        res = icp.icp(pts, snr, closest_with_misses, start_near(rng, truth))
        self.assertTrue(res.converged)
        self.assertFalse(res.inlier[:40].any())
        np.testing.assert_array_equal(res.weights[:40], 0.0)
        self.assertTrue(np.all(np.isfinite(res.covariance)))
        bound = icp.pose_uncertainty(res.covariance, res.center, CORNERS)
        self.assertLess(pose_error(res.transform, truth), 3 * bound)

    def test_a_sphere_leaves_the_turn_about_its_centre_undetermined(self):
        rng = np.random.default_rng(9)
        u = rng.normal(size=(300, 3))
        u = u[u[:, 2] > 0]
        u /= np.linalg.norm(u, axis=1)[:, None]
        pts = 10.0 * u + rng.uniform(-0.006, 0.006, (len(u), 1)) * u

        def sphere(p):
            r = np.linalg.norm(p, axis=1)
            n = p / r[:, None]
            return 10.0 * n, n, r - 10.0
        init = tf.make_transform(tf.rotation_from_vector([0.0, 0.0, 0.3]), [0.5, -0.3, 0.2])
        res = icp.icp(pts, None, sphere, init)
        self.assertTrue(res.converged)
        # The centre is found (any turn about it fits as well), and the bound says the pose
        # is not determined instead of reporting a number.
        np.testing.assert_allclose(res.transform[:3, 3], 0.0, atol=0.002)
        self.assertLess(res.rms, 0.006)
        self.assertTrue(np.isinf(icp.pose_uncertainty(res.covariance, res.center, CORNERS)))

    def test_bad_input(self):
        pts = surface_patch(np.random.default_rng(7), 20)
        with self.assertRaises(InputError):
            icp.icp(pts, -np.ones(20), ellipsoid_closest, np.eye(4))
        with self.assertRaises(InputError):
            icp.icp(pts, np.ones(19), ellipsoid_closest, np.eye(4))
        with self.assertRaises(InputError):
            icp.icp(pts[:5], None, ellipsoid_closest, np.eye(4))


if __name__ == "__main__":
    unittest.main()
