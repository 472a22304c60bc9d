"""SNR-weighted, robust ICP to an exact surface (paper 3.2) and the pose's covariance.

The objective is  sum_i w_i d_i(T)^2  with d_i the signed distance of T p_i to the surface and
w_i = a_i * rho_i:

* a_i = SNR_i / mean(SNR) — the sensor's noise along its beam is
  sigma_i^2 = sigma_ref^2 SNR_ref / SNR_i (docs/contracts.md), the paper's weights; or, with
  ``weight_model`` (core.weights), that model's weights re-evaluated at every pose (the sensor
  model's 1 / sigma_n^2, the noise along the normal: the maximum-likelihood weights). Dividing
  by the mean makes a_i = 1 for a typical point, so sigma0 below is the noise of a typical point.
* rho_i in [0, 1] — a redescending robust weight of the standardised residual
  u_i = |z_i| / s with z_i = d_i sqrt(a_i) and s = max(1.4826 MAD(z), median |z| / k_full),
  a robust scale re-estimated at every iteration (see _robust_deviation). rho = 1 for
  u <= k_full, a biweight-shaped taper to 0 at k_zero, 0 beyond.
  Flat in the core, so the good points are fitted by plain weighted least squares (the
  efficient estimator, and the covariance formula below is exact for them); gross outliers and
  real defects (many sigma away) weigh exactly 0. Two refinements (see robust_selection): a_i is
  floored at 1 / max_noise_ratio^2 inside z (a low SNR lowers the weight, it does not excuse
  a gross error), and rho_i is multiplied by the same taper applied to the mean of the
  (clipped) z over the point's measured neighbourhood (a defect's low flanks are coherent,
  noise is not), less, where the beams are known, the most the sensor's own systematic error
  (ICPOptions.systematic_mm, its stated accuracy) can leave in that mean after the fit, which
  is just as coherent.
  A point is an inlier when rho_i > 0.

Iterations: Horn's closed form against the exact closest points first (robust from a coarse
start, but point-to-point only slides slowly along a smooth surface), then Gauss-Newton steps
of the point-to-plane linearisation d_i + n_i . (dt + dw x (p_i - c)). Because the gradient of
the exact distance is the normal, the Gauss-Newton fixed point is a stationary point of the
exact objective above, not of a surrogate.
"""

import time
from dataclasses import dataclass

import numpy as np

from . import background, bias_take_up
from .errors import InputError
from .weights import normalised_weights
from .transforms import make_transform, rotation_from_vector, rotation_matrix_from_quaternion

MAD_TO_SIGMA = 1.4826   # sigma of a normal distribution per unit of median absolute deviation


@dataclass
class ICPOptions:
    max_iter: int = 60          # closest-point evaluations, Horn and Gauss-Newton together
    horn_iters: int = 5         # point-to-point iterations before the Gauss-Newton steps
    rot_tol: float = 1e-9       # rad: an update below both tolerances has converged
    trans_tol: float = 1e-7     # mm
    k_full: float = 3.0         # robust scales below which a point has full weight
    k_zero: float = 4.5         # robust scales from which a point has no weight
    min_scale: float = 1e-6     # mm: residuals below this are exact data, not noise to scale by
    max_noise_ratio: float = 1.0   # largest noise, in typical points' noise, granted a low SNR
    defect_neighbours: int = 16    # neighbourhood size of the defect test; 0 switches it off
    # mm: the sensor's stated accuracy, the bound of its systematic reading error. Where the
    # beams are known the defect test grants each neighbourhood's mean the field a bias of
    # this size can leave after the fit (robust_selection): that is the sensor's error, not a
    # defect. 0: no sensor known.
    systematic_mm: float = 0.0
    # A last Gauss-Newton step below both is applied to the residuals linearly, without a new
    # closest-point evaluation: their error is curvature * step^2.
    linear_update_mm: float = 1e-4
    linear_update_rad: float = 1e-6
    # Gauss-Newton also stops once the motion still to come, extrapolated from how the last
    # steps shrink, is below this fraction of the pose's own 1 sigma uncertainty (both at the
    # points' extremes). Real parts, whose form errors keep many points in the robust weight's
    # taper band, converge linearly and slowly; iterating on moves the pose by nothing that
    # matters against its uncertainty.
    uncertainty_fraction: float = 0.01
    # Wall-clock budget, s (None: none): iterations stop once it is spent, with
    # ICPResult.stopped saying so, so a fit that is lost ends instead of running for minutes.
    time_limit_s: float = None


@dataclass
class ICPResult:
    transform: np.ndarray       # (4,4) measured -> CAD
    distances: np.ndarray       # (N,) signed residuals at `transform`
    inlier: np.ndarray          # (N,) bool, robust weight > 0
    weights: np.ndarray         # (N,) total weights a_i * rho_i
    rms: float                  # RMS of the inliers' residuals, mm
    sigma0: float               # residual scale of a unit-weight (mean-SNR) point, mm
    iterations: int
    converged: bool
    covariance: np.ndarray      # (6,6) [translation mm, rotation rad] about `center`
    center: np.ndarray          # (3,) weighted centroid of the points in the CAD frame
    split: "PoseSplit" = None   # the covariance of the measured directions, and the others
    stopped: str = ""           # why the iterations ended early: "time limit" or ""
    # The closest points and normals behind `distances` (to first order in the last step, as
    # the distances, when that was applied linearly; see ICPOptions.linear_update_mm).
    closest: np.ndarray = None  # (N,3)
    normals: np.ndarray = None  # (N,3)
    cut: "InlierCut" = None     # where the final weights reach 0 (robust_selection)


def horn(target, source, weights=None):
    """Horn (1987): rotation R and translation t minimising sum w |target - (R source + t)|^2,
    R from the top eigenvector (a unit quaternion) of the symmetric 4x4 matrix N built from the
    weighted cross-covariance of the centred sets."""
    target = np.asarray(target, dtype=float)
    source = np.asarray(source, dtype=float)
    w = np.ones(len(source)) if weights is None else np.asarray(weights, dtype=float)
    wsum = w.sum()
    if wsum <= 0:
        raise InputError("horn: the weights are all zero")
    ct = w @ target / wsum
    cs = w @ source / wsum
    M = ((source - cs) * w[:, None]).T @ (target - ct)   # M[a, b] = sum w s_a t_b
    (sxx, sxy, sxz), (syx, syy, syz), (szx, szy, szz) = M
    N = np.array([
        [sxx + syy + szz, syz - szy, szx - sxz, sxy - syx],
        [syz - szy, sxx - syy - szz, sxy + syx, szx + sxz],
        [szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy],
        [sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz],
    ])
    vals, vecs = np.linalg.eigh(N)
    R = rotation_matrix_from_quaternion(vecs[:, np.argmax(vals)])
    return R, ct - R @ cs


def snr_weights(snr, n):
    if snr is None:
        return np.ones(n)
    snr = np.asarray(snr, dtype=float)
    if snr.shape != (n,):
        raise InputError("icp: snr has shape %s, expected (%d,)" % (snr.shape, n))
    if not np.all(np.isfinite(snr)) or np.any(snr < 0) or snr.sum() <= 0:
        raise InputError("icp: snr must be finite, non-negative and not all zero")
    return snr / snr.mean()


def _taper(u, options):
    """1 up to k_full, a biweight-shaped fall to 0 at k_zero, 0 beyond (and for NaN)."""
    x = np.clip((u - options.k_full) / (options.k_zero - options.k_full), 0.0, 1.0)
    return np.where(u < options.k_zero, (1.0 - x ** 2) ** 2, 0.0)


def _robust_deviation(values, usable, options):
    """|v| / s of every value (inf where not usable), and the robust scale s.

    s = 1.4826 MAD (about the median), but never below median |v| / k_full, so that at least
    half of the points keep full weight. The MAD alone lets ICP leave a wrong pose that fits
    part of the points (their median sits near those, the rest are rejected); the floor keeps
    residuals that all sit to one side, from a start shifted along the surface normal, from
    being rejected all together.
    """
    v = np.abs(values[usable])
    scale = max(MAD_TO_SIGMA * np.median(np.abs(values[usable] - np.median(values[usable]))),
                np.median(v) / options.k_full, options.min_scale)
    return np.where(usable, np.abs(values) / scale, np.inf), scale


def robust_weights(distances, a, options, neighbourhoods=None, bias_response=None):
    """rho_i of the module docstring, and the robust scale s (mm, for a unit-weight point):
    robust_selection's first two.
    """
    rho, scale, _ = robust_selection(distances, a, options, neighbourhoods, bias_response)
    return rho, scale


def robust_selection(distances, a, options, neighbourhoods=None, bias_response=None):
    """(rho_i of the module docstring, the robust scale s (mm, for a unit-weight point), the
    InlierCut of these weights: where each of the two tests gives no weight, None where no
    point is usable).

    `neighbourhoods` (of the measured points) switches on the defect test: the mean of the
    standardised residuals, clipped, over a point's neighbourhood is judged against the robust
    spread of those means. Noise averages out in a neighbourhood, a defect's flank (a real
    deviation of a few sigma, too small for the per-point test) does not, so flanks are
    rejected with the defect instead of tilting the fit; the clipping (at +-k_full s, plus the
    allowance below) keeps a gross outlier from rejecting its neighbours.

    That spread is the noise's, sigma / sqrt(size) (0.9 um for the default sensor). A reading
    bias b, |b| <= the sensor's stated accuracy (options.systematic_mm), moves each point's
    residual by b s_i after the rigid fit has taken up what it can (`bias_response`, s_i =
    beta_i - J_i (J^T W J)^-1 J^T W beta, beta_i = beam . normal; see _bias_response): a smooth
    field reaching several um where the beams meet the surface unlike the rest (edges, grazing
    views), 5-7 spreads, which the test alone would reject as a flank, and reject or keep
    depending on the draw (docs/maintainers.md, "The defect test and the sensor's bias"). So with
    `bias_response` a neighbourhood's mean counts only by what exceeds the most that field can
    put in it, systematic_mm times the mean of |s_i| sqrt(a_i) (z's scaling): a point is
    down-weighted from that + k_full spreads, rejected from that + k_zero spreads. Where the
    sensor's bias cannot move a residual (s_i = 0) nothing is granted; without beams
    (`bias_response` None) nothing either, the test as it was.
    """
    usable = (a > 0) & np.isfinite(distances)
    if not usable.any():
        return np.zeros(len(distances)), np.nan, None
    # The noise model grants a point of low SNR a noise of sigma0 / sqrt(a_i), without bound;
    # but gross errors are what low SNRs bring (docs/contracts.md), so when judging outliers no
    # point is granted more than max_noise_ratio times a typical point's noise (by default none: the
    # SNR lowers a point's weight, it does not excuse its residual).
    root = np.sqrt(np.maximum(a, options.max_noise_ratio ** -2))
    z = np.where(usable, distances * root, np.inf)
    u, scale = _robust_deviation(z, usable, options)
    rho = _taper(u, options)
    cut = InlierCut(root=root, point_cut=options.k_zero * scale)
    if neighbourhoods is not None:
        granted = (0.0 if bias_response is None or options.systematic_mm <= 0 else
                   options.systematic_mm * np.abs(np.nan_to_num(bias_response)) * root)
        limit = options.k_full * scale + granted
        local = neighbourhoods.means(np.clip(z, -limit, limit), usable)
        finite = np.isfinite(local)
        if finite.any():
            spread = _robust_deviation(local, finite, options)[1]
            allowance = (0.0 if np.isscalar(granted)
                         else neighbourhoods.means(np.where(usable, granted, 0.0), usable))
            excess = np.where(finite, np.maximum(np.abs(local) - allowance, 0.0), np.inf)
            rho = rho * _taper(excess / spread, options)
            n = len(distances)
            cut.limit = np.broadcast_to(limit, (n,)).copy()
            cut.allowance = np.broadcast_to(allowance, (n,)).copy()
            cut.neighbourhood_cut = options.k_zero * spread
            cut.neighbourhoods = neighbourhoods
    return rho, scale, cut


@dataclass
class InlierCut:
    """Where robust_selection's weights reach 0, for a model to replay which readings a fit
    keeps (inspection.uncertainty.censored_worst_terms): reading i, of residual d_i, has
    z_i = d_i root_i and is kept (rho_i > 0) when |z_i| < point_cut and, with the defect test,
    when |mean of clip(z_j, +-limit_j) over its neighbourhood| - allowance_i < neighbourhood_cut
    (limit, allowance None: no defect test; ``neighbourhoods``: the test's own, from which
    Neighbourhoods.members gives each reading's, or None where they are not known)."""
    root: np.ndarray                   # (N,)
    point_cut: float
    limit: np.ndarray = None           # (N,)
    allowance: np.ndarray = None       # (N,)
    neighbourhood_cut: float = np.inf
    neighbourhoods: "Neighbourhoods" = None   # the defect test's own

    def rows(self, rows):
        """The cut of some readings only (their neighbourhoods' tests stay as fitted; the
        neighbourhoods themselves, windows of the whole cloud, are not kept)."""
        pick = (lambda v: None if v is None else v[rows])
        return InlierCut(self.root[rows], self.point_cut, pick(self.limit),
                         pick(self.allowance), self.neighbourhood_cut)

    def kept(self, values, index, judged, neighbours):
        """(draws, len(judged)) bool: which readings the fit would keep, for ``values`` (draws,
        m) residuals of its readings ``index`` (m,); ``judged``: the positions (in m) of the
        readings to decide, ``neighbours`` (len(judged), k) the positions of each one's
        neighbourhood (with the defect test)."""
        index = np.asarray(index)
        z = values * self.root[index]
        keep = np.abs(z[:, judged]) < self.point_cut
        if self.limit is not None:
            limit = self.limit[index]
            local = np.clip(z, -limit, limit)[:, neighbours].mean(axis=2)
            excess = np.maximum(np.abs(local) - self.allowance[index][judged], 0.0)
            keep &= excess < self.neighbourhood_cut
        return keep


def _bias_response(moved, normals, beams_cad, a, max_incidence_rad=None):
    """(N,) s_i: each residual's change per unit reading bias once a weighted (``a``) rigid
    fit has taken up what it can, s_i = beta_i - J_i r, r = core.bias_take_up.take_up (the
    model of uncertainty.systematic_coefficients, at this pose; 0 where a_i = 0 or beta_i is
    not finite, everywhere when fewer than 7 points take part). An edge foot (a beam meeting
    its normal more obliquely than ``max_incidence_rad``) takes up nothing (take_up). The
    weights are the a_i before the robust factor, which this very s_i goes into, and r is about
    the a-weighted centroid of the points taking part (s does not depend on the centre)."""
    beta = bias_take_up.beam_normal(normals, beams_cad)
    keep = (a > 0) & np.isfinite(beta)
    s = np.zeros(len(beta))
    fit = bias_take_up.takes_part(moved, normals, beams_cad, a, max_incidence_rad)
    if np.count_nonzero(fit) < 7:
        return s
    w = a[fit]
    center = w @ moved[fit] / w.sum()
    r = bias_take_up.take_up(moved, normals, beams_cad, a, center, max_incidence_rad)
    s[keep] = bias_take_up.left_over(moved[keep], normals[keep], beams_cad[keep], r, center)
    return s


class Neighbourhoods:
    """Each measured point's neighbourhood: the `size` points around it along a Morton
    (Z-order) curve through the cloud. Neighbours along the curve are near in space (but for
    the curve's rare long jumps), and a mean over a sliding window costs two cumulative sums,
    where k-nearest neighbours of a few hundred thousand points would cost seconds. The points
    move rigidly during ICP, so the order is computed once."""

    LEVELS = 1 << 10   # grid steps per axis for the curve (30-bit codes)

    def __init__(self, points, size):
        lo = points.min(axis=0)
        step = max(float(np.max(points.max(axis=0) - lo)), 1e-9) / (self.LEVELS - 1)
        ijk = np.minimum(((points - lo) / step).astype(np.int64), self.LEVELS - 1)
        code = (self._spread(ijk[:, 0]) << 2) | (self._spread(ijk[:, 1]) << 1) \
            | self._spread(ijk[:, 2])
        self._along(np.argsort(code, kind="stable"), size)

    @classmethod
    def from_order(cls, order, size):
        """The neighbourhoods of a cloud whose curve order is known (``order``, as kept by
        InlierCut), without its points."""
        hoods = cls.__new__(cls)
        hoods._along(np.asarray(order, dtype=np.int64), size)
        return hoods

    def _along(self, order, size):
        self.order = order
        n = len(order)
        self.size = min(size, n)
        # Window start of each position along the curve, the window centred where possible.
        self._start = np.clip(np.arange(n) - self.size // 2, 0, n - self.size)

    def members(self, index):
        """(len(index), size) the points of each point's neighbourhood (``means``' window)."""
        position = np.empty(len(self.order), dtype=np.int64)
        position[self.order] = np.arange(len(self.order))
        start = self._start[position[np.asarray(index, dtype=np.int64)]]
        return self.order[start[:, None] + np.arange(self.size)]

    @staticmethod
    def _spread(v):
        """The 10 bits of v moved to every third bit (Morton interleaving)."""
        v = v & 0x3FF
        v = (v | (v << 16)) & 0x030000FF
        v = (v | (v << 8)) & 0x0300F00F
        v = (v | (v << 4)) & 0x030C30C3
        v = (v | (v << 2)) & 0x09249249
        return v

    def means(self, values, usable):
        """Mean of `values` over each point's neighbourhood, counting usable points only (NaN
        where a neighbourhood has none)."""
        ordered = np.where(usable, values, 0.0)[self.order]
        sums = np.concatenate([[0.0], np.cumsum(ordered)])
        counts = np.concatenate([[0], np.cumsum(usable[self.order])])
        end = self._start + self.size
        with np.errstate(invalid="ignore", divide="ignore"):
            along = (sums[end] - sums[self._start]) / (counts[end] - counts[self._start])
        result = np.empty(len(values))
        result[self.order] = along
        return result


def _extremes(points):
    """The corners of the points' bounding box."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                     for z in (lo[2], hi[2])])


def _extreme_motion(points, center, dt, dw):
    """Largest displacement of a corner of the points' bounding box under the small motion."""
    v = _extremes(points) - center
    return float(np.linalg.norm(dt + np.cross(dw, v), axis=1).max())


def pose_information(points_cad, normals, weights, residuals, center):
    """(H, s^2, n_w): the pose's Fisher information H = sum w_i J_i^T J_i,
    J_i = [n_i, (p_i - c) x n_i], the unit-weight residual variance
    s^2 = sum w_i r_i^2 / (n_w - 6), and n_w, the number of points with w_i > 0
    (H None when n_w <= 6: too few points for any covariance)."""
    w = np.asarray(weights, dtype=float)
    r = np.asarray(residuals, dtype=float)
    keep = w > 0
    n_w = int(np.count_nonzero(keep))
    if n_w <= 6:
        return None, np.inf, n_w
    J = bias_take_up.rigid_jacobian(np.asarray(points_cad)[keep], np.asarray(normals)[keep], center)
    H = (J * w[keep, None]).T @ J
    return H, float(np.sum(w[keep] * r[keep] ** 2)) / (n_w - 6), n_w


@dataclass
class PoseSplit:
    """The pose's covariance split into the directions the points measure and those they do
    not (see split_information). Motions are (translation mm, rotation rad) about the
    covariance's centre, in the CAD frame."""
    covariance: np.ndarray   # (6,6) covariance of the measured directions (0 in the others)
    unmeasured: np.ndarray   # (6,k) orthonormal basis of the unmeasured directions in
    #                          (translation mm, rotation rad * length) units
    length: float            # mm: the points' extent, the scale of rotations and the threshold
    eigenvalues: np.ndarray  # (6,) of the scaled information, ascending

    @property
    def complete(self):
        return self.unmeasured.shape[1] == 0


def split_information(H, s2, length, n_terms):
    """Eigen-decomposition of the Fisher information H with rotations scaled by ``length``
    (y = [t, length * w], so every coordinate is a displacement in mm at the points' extent).

    A direction of eigenvalue lambda has a 1 sigma of sqrt(s^2 / lambda) mm. It is unmeasured
    when that exceeds ``length`` itself - the points cannot place the part even to within its
    own size, so the linearised covariance says nothing there - or when lambda is below the
    rounding of the sum that built H (n_terms * eps * lambda_max; this is what an exact
    symmetry gives, and what catches it when s^2 = 0, noiseless data). The covariance is the
    inverse restricted to the measured eigen-directions (a pseudo-inverse); it equals
    s^2 H^-1 when every direction is measured."""
    length = float(length)
    scale = np.r_[np.ones(3), np.full(3, length)]
    Hy = H / np.outer(scale, scale)
    values, vectors = np.linalg.eigh(Hy)
    floor = max(s2 / length ** 2 if np.isfinite(s2) else 0.0,
                n_terms * np.finfo(float).eps * max(values[-1], 0.0))
    measured = values > floor
    inv = (vectors[:, measured] / values[measured]) @ vectors[:, measured].T
    cov = s2 * inv / np.outer(scale, scale)
    return PoseSplit(covariance=cov, unmeasured=vectors[:, ~measured], length=length,
                     eigenvalues=values)


def _extent(points):
    return max(float(np.linalg.norm(np.ptp(points, axis=0))), 1e-9)


def pose_split(points_cad, normals, weights, residuals, center):
    """split_information of the points' own Fisher information, ``length`` their extent
    (bounding-box diagonal). None when too few points carry weight."""
    H, s2, n_w = pose_information(points_cad, normals, weights, residuals, center)
    if H is None:
        return None
    keep = np.asarray(weights) > 0
    return split_information(H, s2, _extent(np.asarray(points_cad)[keep]), n_w)


def pose_covariance(points_cad, normals, weights, residuals, center):
    """C = s^2 (sum w_i J_i^T J_i)^-1, J_i = [n_i, (p_i - c) x n_i],
    s^2 = sum w_i r_i^2 / (n_w - 6), n_w = number of points with w_i > 0.

    With w = a * rho this is the weighted least-squares covariance of the points the robust
    weight keeps: exact when rho is 0 or 1 (all but the few points in the taper band); s^2 is
    the variance of a unit-weight residual, so the weights' normalisation cancels out.
    Infinite when the points do not fix all six degrees of freedom (e.g. a sphere; the rule is
    split_information's, and pose_split gives the covariance of the directions they do fix).
    """
    split = pose_split(points_cad, normals, weights, residuals, center)
    if split is None or not split.complete:
        return np.full((6, 6), np.inf)
    return split.covariance


def random_residual_share(weights, residuals, n_parameters=6):
    """s_d^2 / s^2, at most 1, of a fit's residuals in acquisition order (the points with
    weight > 0): s^2 = sum w r^2 / (n - k) is the unit-weight variance pose_covariance scales
    by, s_d^2 = mean((z_(i+1) - z_i)^2) / 2 of the weighted residuals z = sqrt(w) r in their
    order. A misfit that changes slowly from reading to reading (the part of a reading bias
    the rigid fit cannot take up, a defect, form error) cancels in the differences and stays in
    s^2; white noise is in both. Points in no spatial order give ~1. 1 when it is undefined.

    Why: an uncertainty budget that carries the sensor's bias as its own term would count it
    twice through a pose covariance scaled by s^2 (Rotor 67's planned scan, a 6 um bias: the
    covariance's 1 sigma 1.8x the noise-only one; docs/maintainers.md, "The pose term's scale")."""
    w = np.asarray(weights, dtype=float)
    r = np.asarray(residuals, dtype=float)
    keep = np.isfinite(w) & np.isfinite(r) & (w > 0)
    z = np.sqrt(w[keep]) * r[keep]
    if len(z) <= n_parameters + 1:
        return 1.0
    s2 = float(np.sum(z ** 2)) / (len(z) - n_parameters)
    s2d = float(np.sum(np.diff(z) ** 2)) / (2.0 * (len(z) - 1))
    if not (s2 > 0 and np.isfinite(s2) and np.isfinite(s2d)):
        return 1.0
    return min(1.0, s2d / s2)


def pose_uncertainty(cov, center, corners):
    """1 sigma displacement at the worst corner: a corner x moves by dt + dw x (x - c), i.e.
    J_x [dt, dw] with J_x = [I, -[x - c]_x]; its RMS is sqrt(trace(J_x C J_x^T)).
    Infinite when the covariance is (the points do not determine the pose)."""
    cov = np.asarray(cov, dtype=float)
    if not np.all(np.isfinite(cov)):
        return float("inf")
    worst = 0.0
    for x in np.asarray(corners, dtype=float):
        v = x - np.asarray(center, dtype=float)
        skew = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
        Jx = np.hstack([np.eye(3), -skew])
        worst = max(worst, float(np.sqrt(np.trace(Jx @ cov @ Jx.T))))
    return worst


def _rotation_angle(R):
    """Angle of a rotation, accurate near 0 (where arccos of the trace is not)."""
    sin_angle = 0.5 * np.linalg.norm([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    return float(np.arctan2(sin_angle, 0.5 * (np.trace(R) - 1.0)))


def _gauss_newton_step(points_cad, normals, distances, w, center):
    """Small motion (dt, dw) about `center` minimising sum w (d + J [dt, dw])^2; the
    least-squares solver leaves directions the surface does not fix (rank deficiency) alone."""
    keep = w > 0
    J = bias_take_up.rigid_jacobian(points_cad[keep], normals[keep], center)
    sw = np.sqrt(w[keep])
    x = np.linalg.lstsq(J * sw[:, None], -distances[keep] * sw, rcond=1e-12)[0]
    return x[:3], x[3:]


def icp(points, snr, closest_fn, init, options=None, weight_model=None, beams=None):
    """Register `points` (measured frame) to the surface behind `closest_fn`, starting at `init`
    (measured -> CAD). See the module docstring for the objective and the weights;
    ``weight_model(T, normals) -> (N,)`` (core.weights.SensorWeights), when given, replaces the
    SNR weights a_i and is re-evaluated at every closest-point evaluation. ``beams`` (N,3):
    each reading's beam in the measured frame (default: the weight model's, if it has them),
    from which the defect test grants the field the sensor's bias can leave (robust_selection)."""
    options = options or ICPOptions()
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3 or len(points) < 7:
        raise InputError("icp: need at least 7 points of shape (N, 3), got %s"
                         % (points.shape,))
    a = snr_weights(snr, len(points))
    neighbourhoods = (Neighbourhoods(points, options.defect_neighbours)
                      if 0 < options.defect_neighbours < len(points) else None)
    if beams is None:
        beams = getattr(weight_model, "beam", None)
    if beams is not None:
        beams = np.asarray(beams, dtype=float)
        if beams.shape != points.shape:
            raise InputError("icp: beams have shape %s, expected %s"
                             % (beams.shape, points.shape))

    def bias_response(T, moved, normals):
        if beams is None or neighbourhoods is None or options.systematic_mm <= 0:
            return None
        return _bias_response(moved, normals, beams @ T[:3, :3].T, a,
                              getattr(weight_model, "max_incidence_rad", None))
    T = np.array(init, dtype=float)
    converged = False
    iterations = 0
    last_step = None   # (moved, normals, distances, center, dt, dw) of the last Gauss-Newton step
    previous_motion = np.nan
    stopped = ""
    started = time.monotonic()
    while iterations < options.max_iter:
        background.tick()    # a GUI's event loop turns between iterations
        if options.time_limit_s is not None \
                and time.monotonic() - started >= options.time_limit_s:
            stopped = "time limit"
            break
        moved = points @ T[:3, :3].T + T[:3, 3]
        closest, normals, distances = closest_fn(moved)
        iterations += 1
        if weight_model is not None:   # sensor-model weights (core.weights)
            a = normalised_weights(weight_model, T, normals, len(points))
        rho, _, _ = robust_selection(distances, a, options, neighbourhoods,
                                     bias_response(T, moved, normals))
        w = a * rho
        if np.count_nonzero(w) < 7:
            last_step = None
            break
        center = w @ moved / w.sum()
        if iterations <= options.horn_iters:
            keep = w > 0   # a point without a usable distance may have no closest point
            R, t = horn(closest[keep], moved[keep], w[keep])
            last_step = None
            size = (np.linalg.norm(t + R @ center - center), _rotation_angle(R))
            T = make_transform(R, t) @ T
        else:
            dt, dw = _gauss_newton_step(moved, normals, distances, w, center)
            R = rotation_from_vector(dw)
            last_step = (moved, normals, distances, center, dt, dw)
            size = (np.linalg.norm(dt), np.linalg.norm(dw))
            T = make_transform(R, center + dt - R @ center) @ T
            motion = _extreme_motion(moved, center, dt, dw)
            rate = motion / previous_motion      # nan after the first step
            previous_motion = motion
            if rate < 0.95 and options.uncertainty_fraction > 0:
                sigma = pose_uncertainty(pose_covariance(moved, normals, w, distances, center),
                                         center, _extremes(moved))
                if motion * rate / (1.0 - rate) < options.uncertainty_fraction * sigma:
                    converged = True
                    break
        if size[0] < options.trans_tol and size[1] < options.rot_tol:
            converged = True
            break

    if last_step is not None and np.linalg.norm(last_step[4]) < options.linear_update_mm \
            and np.linalg.norm(last_step[5]) < options.linear_update_rad:
        # The residuals at the returned pose to first order in the last small step, which
        # saves a closest-point evaluation of the whole cloud.
        moved_before, normals, distances, center, dt, dw = last_step
        distances = distances + bias_take_up.rigid_jacobian(moved_before, normals, center) @ np.r_[dt, dw]
        moved = points @ T[:3, :3].T + T[:3, 3]
        # The foot point that goes with that distance: the point less it along the normal
        # (the foot moved along the tangent plane), where the true one is within curvature x
        # distance x step.
        closest = moved - distances[:, None] * normals
    else:
        moved = points @ T[:3, :3].T + T[:3, 3]
        closest, normals, distances = closest_fn(moved)
    if weight_model is not None:   # sensor-model weights (core.weights)
        a = normalised_weights(weight_model, T, normals, len(points))
    rho, _, cut = robust_selection(distances, a, options, neighbourhoods,
                                   bias_response(T, moved, normals))
    w = a * rho
    inlier = rho > 0
    center = w @ moved / w.sum() if w.sum() > 0 else moved.mean(axis=0)
    split = pose_split(moved, normals, w, distances, center)
    cov = (split.covariance if split is not None and split.complete
           else np.full((6, 6), np.inf))
    keep = w > 0
    dof = max(int(np.count_nonzero(keep)) - 6, 1)
    return ICPResult(
        transform=T, distances=distances, inlier=inlier, weights=w,
        rms=float(np.sqrt(np.mean(distances[inlier] ** 2))) if inlier.any() else float("nan"),
        sigma0=float(np.sqrt(np.sum(w[keep] * distances[keep] ** 2) / dof)),
        iterations=iterations, converged=converged, covariance=cov, center=center,
        split=split, stopped=stopped, closest=closest, normals=normals, cut=cut)
