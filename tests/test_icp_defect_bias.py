"""core.icp's neighbourhood defect test against the sensor's own systematic error: a reading
bias of the stated accuracy (a smooth field the rigid fit cannot take up) is not a defect, and
a real bump still is. Truth: the triaxial ellipsoid of tests/test_icp.py read all round (a
blade is), its exact closest points, a bias built from known beams, the weighted least-squares
pose response to that bias solved here from the true points and normals, and exact
k-nearest-neighbour means in place of core.icp's Morton-curve neighbourhoods."""
import unittest

import numpy as np

from BladeInspect.core import icp
from BladeInspect.core import transforms as tf
from tests.test_icp import AXES, CORNERS, ellipsoid_closest, pose_error, start_near

ACCURACY = 0.006          # mm: the default sensor's stated accuracy (rig.sensor.SensorModel)
# A rotary axis along x, the ellipsoid's long axis (a blade's span): eight beams 45 degrees
# apart in the y-z plane, each point read by the one most nearly head-on, and not at all
# beyond MAX_INCIDENCE (the sensor's coverage). The bias along the normal, b beam . n, is then
# b cos(<= 22.5 deg) over most of the part and falls towards b cos MAX_INCIDENCE at its two
# ends, read ever more obliquely: a smooth field whose departure from the part's common
# level reaches the stated accuracy's size on a minority of the points, as on a blade's edges.
VIEWS = np.array([[0.0, np.cos(t), np.sin(t)] for t in np.radians(np.arange(0, 360, 45))])
MAX_INCIDENCE = np.radians(85.0)   # rig.sensor.SensorModel: coverage 170 deg


def beams_of(normals):
    """Unit beam (sensor towards the surface) of each point: the view most against its normal."""
    return VIEWS[np.argmin(normals @ VIEWS.T, axis=1)]


def surface(rng, n):
    """n points all round the ellipsoid that the views read."""
    out, count = [], 0
    while count < n:
        u = rng.normal(size=(2 * n, 3))
        p = u / np.linalg.norm(u, axis=1)[:, None] * AXES
        _, normals, _ = ellipsoid_closest(p)
        seen = -np.einsum("ij,ij->i", beams_of(normals), normals) > np.cos(MAX_INCIDENCE)
        out.append(p[seen])
        count += len(out[-1])
    return np.concatenate(out)[:n]


def scan(rng, n, bias_mm, bump=None):
    """(measured points, truth, CAD points, normals, beams in the CAD frame): noise uniform in +-ACCURACY along
    the normal, every reading lengthened by ``bias_mm`` (the point moved by bias * beam), and
    ``bump`` (n,) mm of raised material along the normal where given."""
    cad = surface(rng, n)
    _, normals, _ = ellipsoid_closest(cad)
    beams = beams_of(normals)
    offset = rng.uniform(-ACCURACY, ACCURACY, n)
    if bump is not None:
        offset = offset + bump(cad)
    truth = tf.random_transform(rng, 100.0)
    measured = cad + offset[:, None] * normals + bias_mm * beams
    return tf.apply_transform(tf.invert_transform(truth), measured), truth, cad, normals, beams


def measured_beams(beams, truth):
    """The beams in the measured frame, as a rig reports them."""
    return beams @ truth[:3, :3]


def linear_response(cad, normals, beams, bias_mm, weights):
    """Corner motion of the weighted least-squares pose step that removes residuals
    bias * beam . n (the fit's first-order take-up of the bias), about the points' centroid."""
    c = weights @ cad / weights.sum()
    J = np.hstack([normals, np.cross(cad - c, normals)])
    r = bias_mm * np.einsum("ij,ij->i", beams, normals)
    sw = np.sqrt(weights)
    x = np.linalg.lstsq(J * sw[:, None], -r * sw, rcond=None)[0]
    return x[:3] + np.cross(x[3:], CORNERS - c)


def bias_field(cad, normals, beams, weights):
    """(n,) s_i: each residual's change per unit bias once the weighted least-squares rigid
    fit has taken up what it can (solved here from the truth)."""
    c = weights @ cad / weights.sum()
    J = np.hstack([normals, np.cross(cad - c, normals)])
    beta = np.einsum("ij,ij->i", beams, normals)
    sw = np.sqrt(weights)
    return beta - J @ np.linalg.lstsq(J * sw[:, None], beta * sw, rcond=None)[0]


def corner_motion(T_after, T_before):
    delta = T_after @ tf.invert_transform(T_before)
    return tf.apply_transform(delta, CORNERS) - CORNERS


class TestDefectTestAndSensorBias(unittest.TestCase):
    N_BIAS = 6000
    N_BUMP = 20000   # 4 points / mm^2, as a planned scan reads a blade

    def test_a_bias_of_the_stated_accuracy_rejects_nothing(self):
        rng = np.random.default_rng(21)
        with_allowance = icp.ICPOptions(systematic_mm=ACCURACY)
        for trial in range(2):
            seed = int(rng.integers(1 << 30))
            fits = {}
            for b in (0.0, ACCURACY, -ACCURACY):
                # the same points, noise and frame for every bias: only the bias differs
                pts, truth, cad, normals, beams = scan(np.random.default_rng(seed), self.N_BIAS, b)
                init = start_near(np.random.default_rng(seed + 1), truth)
                fits[b] = icp.icp(pts, None, ellipsoid_closest, init, with_allowance,
                                  beams=measured_beams(beams, truth))
                self.assertTrue(fits[b].converged)
                # Nothing here is a defect or a gross error: every point keeps its weight.
                self.assertTrue(fits[b].inlier.all(), "trial %d, bias %g: %d rejected" % (
                    trial, b, np.count_nonzero(~fits[b].inlier)))
            # With every point kept the fit takes up the bias as weighted least squares does:
            # the pose moves by the linear response computed from the truth (its error is the
            # bias's second order, curvature * b^2, and the noise's effect on J).
            for b in (ACCURACY, -ACCURACY):
                moved = corner_motion(fits[b].transform, fits[0.0].transform)
                expected = linear_response(cad, normals, beams, b, np.ones(self.N_BIAS))
                scale = np.max(np.linalg.norm(expected, axis=1))
                self.assertGreater(scale, 1e-4)   # a take-up, not nothing
                self.assertLess(np.max(np.linalg.norm(moved - expected, axis=1)),
                                0.02 * scale + 2e-5, "trial %d, bias %g" % (trial, b))

    def test_a_bump_is_still_rejected_with_the_bias_on_top(self):
        rng = np.random.default_rng(22)
        options = icp.ICPOptions(systematic_mm=ACCURACY)
        flank_kept = flank_total = 0
        shifts = []
        for trial in range(3):
            seed = int(rng.integers(1 << 30))
            # 0.05 mm high, cos^2 profile of radius 3 mm (28 mm^2, some 100 points)
            centre = surface(np.random.default_rng(seed + 2), 1)[0]
            radius = 3.0

            def bump(cad):
                r = np.linalg.norm(cad - centre, axis=1)
                return np.where(r < radius, 0.05 * np.cos(0.5 * np.pi * r / radius) ** 2, 0.0)
            for b in (0.0, ACCURACY, -ACCURACY):
                pts, truth, cad, normals, beams = scan(np.random.default_rng(seed), self.N_BUMP,
                                                       b, bump)
                height = bump(cad)
                init = start_near(np.random.default_rng(seed + 1), truth)
                seen = measured_beams(beams, truth)
                res = icp.icp(pts, None, ellipsoid_closest, init, options, beams=seen)
                without_bump = scan(np.random.default_rng(seed), self.N_BUMP, b)[0]
                clean = icp.icp(without_bump, None, ellipsoid_closest, init, options, beams=seen)
                self.assertTrue(res.converged)
                self.assertGreater(np.count_nonzero(height > 0.03), 10)
                self.assertFalse(res.inlier[height > 0.03].any(), "trial %d bias %g" % (trial, b))
                # The flank (12-30 um: 2-5 noise sigma of one reading, mostly inside the
                # per-point test) is the neighbourhood test's, where what it reads, height + the
                # bias's field b s, stands clear of what that field could be, accuracy |s|
                # (a bias against the bump lowers it as it lowers everything there).
                s_bias = bias_field(cad, normals, beams, np.ones(self.N_BUMP))
                clear = height + b * s_bias - ACCURACY * np.abs(s_bias) > 0.006
                flank = (height > 0.012) & (height <= 0.03) & clear
                flank_kept += np.count_nonzero(res.inlier[flank])
                flank_total += np.count_nonzero(flank)
                # Away from the bump every point is kept. The bump's foot, within the sensor's
                # accuracy of its surroundings, is kept as the sensor's own error would be, and
                # tilts the fit as that would: by about the pose's 1 sigma at most.
                far = np.linalg.norm(cad - centre, axis=1) > 2 * radius
                self.assertGreater(np.mean(res.inlier[far]), 0.999)
                bound = icp.pose_uncertainty(res.covariance, res.center, CORNERS)
                shifts.append(pose_error(res.transform, clean.transform) / bound)
        self.assertLess(flank_kept / flank_total, 0.25, "%d of %d" % (flank_kept, flank_total))
        self.assertLess(max(shifts), 1.5)
        self.assertLess(np.mean(shifts), 0.8)

    def test_the_rule_grants_the_stated_accuracy_and_no_more(self):
        # robust_weights alone, on a plane: a disc of coherent offset just inside, and well
        # outside, what a bias of the stated accuracy can leave there (bias_response s = 1 in
        # the disc: all of it), noise elsewhere; exact 16-nearest-neighbour means.
        rng = np.random.default_rng(23)
        n = 3000
        pts = rng.uniform(0.0, 30.0, (n, 3)) * [1.0, 1.0, 0.0]
        hoods = NearestMeans(pts, 16)
        noise = rng.uniform(-ACCURACY, ACCURACY, n)
        r = np.linalg.norm(pts[:, :2] - 15.0, axis=1)
        patch, core = r < 4.0, r < 2.5      # the core's neighbourhoods lie in the disc
        spread = np.std(noise) / 4.0         # a 16-point mean's noise, 0.87 um
        with_allowance = icp.ICPOptions(systematic_mm=ACCURACY)
        full = np.ones(n)
        for level, rejected in ((ACCURACY - 0.5 * spread, False),
                                (ACCURACY + 8.0 * spread, True)):
            d = noise + np.where(patch, level, 0.0)
            rho, _ = icp.robust_weights(d, np.ones(n), with_allowance, hoods, full)
            self.assertEqual(np.mean(rho[core] > 0), 0.0 if rejected else 1.0,
                             "offset %.1f um" % (1e3 * level))
            self.assertTrue(np.all(rho[r > 6.0] > 0))   # noise alone: all kept
            # Without an allowance (no sensor, or no beams) both are many spreads off.
            for options, response in ((icp.ICPOptions(), full), (with_allowance, None)):
                rho0, _ = icp.robust_weights(d, np.ones(n), options, hoods, response)
                self.assertLess(np.mean(rho0[core] > 0), 0.15)
        # Where the fit takes up the bias whole (s = 0) nothing is granted; where it takes up
        # half (s = 0.5), half the accuracy.
        for s_disc, level, kept in ((0.0, ACCURACY - 0.5 * spread, False),
                                    (0.5, 0.5 * ACCURACY - 0.5 * spread, True),
                                    (0.5, 0.5 * ACCURACY + 8.0 * spread, False)):
            d = noise + np.where(patch, level, 0.0)
            rho, _ = icp.robust_weights(d, np.ones(n), with_allowance, hoods,
                                        np.where(patch, s_disc, 1.0))
            if kept:
                self.assertEqual(np.mean(rho[core] > 0), 1.0, "s = %g" % s_disc)
            else:
                self.assertLess(np.mean(rho[core] > 0), 0.15, "s = %g" % s_disc)
        d = noise + np.where(patch, ACCURACY - 0.5 * spread, 0.0)
        # The allowance is in z's units, d sqrt(a): a point of weight a is granted
        # accuracy * |s| * sqrt(a) (its bias, like its noise, is that many of its own sigmas).
        rho, _ = icp.robust_weights(0.5 * d, np.full(n, 4.0), with_allowance, hoods, full)
        self.assertEqual(np.mean(rho[core] > 0), 1.0)


class NearestMeans:
    """Exact k-nearest-neighbour means (brute force), with core.icp.Neighbourhoods' interface."""

    def __init__(self, points, k):
        gaps = np.linalg.norm(points[:, None] - points[None, :], axis=2)
        self.index = np.argsort(gaps, axis=1)[:, :k]

    def means(self, values, usable):
        v = np.where(usable, values, 0.0)[self.index]
        c = usable[self.index].sum(axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            return v.sum(axis=1) / c



class TestTakeUpWithoutEdgeFeet(unittest.TestCase):
    """core.icp._bias_response leaves out of the take-up a point whose beam meets its normal
    more obliquely than the sensor reads (an edge foot, normal p - c): the others' s_i are
    those of the weighted least-squares take-up over them alone, solved here directly."""

    def test_an_edge_foot_takes_up_nothing(self):
        rng = np.random.default_rng(7)
        n = 400
        pts = rng.uniform(-20.0, 20.0, (n, 3))
        normals = rng.normal(size=(n, 3))
        normals /= np.linalg.norm(normals, axis=1)[:, None]
        beams = normals + 0.3 * rng.normal(size=(n, 3))
        beams /= np.linalg.norm(beams, axis=1)[:, None]
        a = rng.uniform(0.5, 1.5, n)
        # the edge foot: its beam square to its "normal", and a grazing-floor weight
        side = np.cross(normals[0], [0.0, 0.0, 1.0])
        beams[0] = side / np.linalg.norm(side)
        a[0] = 1000.0
        max_incidence = np.radians(85.0)
        s = icp._bias_response(pts, normals, beams, a, max_incidence)

        fit = np.arange(1, n)
        beta = np.einsum("ij,ij->i", beams, normals)
        c = a[fit] @ pts[fit] / a[fit].sum()
        J = np.hstack([normals, np.cross(pts - c, normals)])
        Jw = J[fit] * np.sqrt(a[fit])[:, None]
        r = np.linalg.lstsq(Jw, beta[fit] * np.sqrt(a[fit]), rcond=None)[0]
        np.testing.assert_allclose(s, beta - J @ r, rtol=0, atol=1e-9)
        # with the edge foot in the take-up (no incidence limit) the answer is another
        s_all = icp._bias_response(pts, normals, beams, a)
        self.assertGreater(np.max(np.abs(s_all[fit] - s[fit])), 1e-3)


if __name__ == "__main__":
    unittest.main()
