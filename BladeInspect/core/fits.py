"""Fit objectives for the registration's last step: least squares, minimax (minimum zone) and
fit to the tolerance zone, each with any subset of the six degrees of freedom free.

Every fit starts from a pose ``init`` (measured -> CAD; normally the robust least-squares ICP
result, core.icp) and moves it on the same surface interface as the ICP: a callback
``closest_fn(points_cad) -> (closest (N,3), normals (N,3), signed distances (N,))`` whose
distances are exact and whose normals are the distance's gradient. The points taking part (the
inliers) are those of positive ``weights`` (ICPResult.weights): every fit judges the same
points, chosen once by the ICP's robust weight; only the pose changes.

Parametrisation (what a locked degree of freedom means)
    The pose is  T(xi) = G(xi) T0  with T0 = ``init`` and G(xi) the rigid motion of the CAD
    frame  x -> c + R(w) (x - c) + t,  xi = (t, w) a twist: t a translation (mm) and w a
    rotation vector (rad, R(w) its exponential) about the fixed centre c (``center``; by
    default the weighted centroid of the inliers at T0, in the CAD frame). xi = B theta with B
    the (6, k) basis of the free degrees of freedom (FreeDOF) and theta the k fitted
    parameters. With the CAD-axis names (tx ... rz) the components of xi outside the free ones
    are exactly 0 (not small: B's rows for them are zero), so a locked translation keeps the
    point c where T0 put it and a locked rotation keeps the part's attitude about c; with a
    named direction (r_<axis>, t_<axis>) xi lies exactly in the span of the free directions. A rotation about a line (the engine axis)
    is a rotation about a direction with ``center`` on that line.

Objectives (d_i the signed deviation of inlier i at T(xi))
    least squares  min sum w_i z_i d_i^2, w_i the ICP's weights and z_i region (zone)
                   multipliers (per_zone), by Gauss-Newton.
    least squares with size (SIZE_OBJECTIVE)  min sum w_i z_i (d_i - s)^2 over the pose and
                   a uniform offset s of the whole surface along its normals (mm, + is
                   material added: the part oversize all round). Without s, a uniform size
                   error is partly taken up by the pose (on a twisted blade, a screw along the
                   span; size_take_up); with it the pose is that of the part's form and s is
                   its size deviation. Gauss-Newton with one more Jacobian column, -1 for
                   every point.
    minimax        min max |d_i| (the Chebyshev or minimum-zone fit; unweighted: every inlier
                   must lie in the zone).
    tolerance      max min s_i with s_i = min(d_i - lower_i, upper_i - d_i) the slack of point i
                   in its tolerance zone [lower_i, upper_i]. min s >= 0: the part fits its
                   tolerance, with that margin (mm); min s < 0: no pose found fits it and -min s
                   is the least possible largest violation (mm). Minimax is the case
                   lower = upper = 0 (its slack is -|d|).
    The two Chebyshev objectives are solved by sequential linear programming: linearise d
    about the current pose (the exact Jacobian of the parametrisation above), solve the
    linear max-min problem as a linear programme (HiGHS dual simplex) inside a trust region,
    accept the step when the exact objective improves, repeat until the linear programme
    predicts no gain. Its constraints are exchanged (cutting planes): the programme holds only
    the most binding points, and points the step would violate are added until none is, so
    its size stays in the hundreds for any number of points.

Covariance (``FitResult.covariance``, 6x6 [t mm, w rad] about ``center``, zero in the locked
rows and columns)
    least squares  the sandwich  s^2 H^-1 (sum w z^2 J^T J) H^-1,  H = sum w z J^T J, with
                   J the Jacobian in the free parameters and s^2 = sum w d^2 / (n - k) the
                   variance of a unit-weight residual: the weights w are the noise model's
                   (inverse variances), so with all z = 1 this is ICP's s^2 H^-1; zone
                   multipliers are not the noise model and the sandwich keeps it honest.
    least squares with size  the same sandwich over the k + 1 parameters; the pose block is
                   ``covariance`` and s's variance ``size_variance``.
    minimax, tolerance  the same least-squares covariance (z = 1) of the same free degrees of
                   freedom at the fit's pose. It states what the measurement determines, not the
                   scatter of the Chebyshev estimator, which for Gaussian noise is larger (it
                   rests on the few extreme points); ``covariance_kind`` says which it is.
"""

import re
from dataclasses import dataclass
from typing import Optional

import numpy as np
from scipy.optimize import linprog

from .errors import InputError
from .transforms import make_transform, rotation_from_vector

OBJECTIVES = ("least-squares", "minimax", "tolerance")
# Not among OBJECTIVES, which are fitted side by side for the fit-sensitivity table: the size
# fit answers another question (form and size apart), asked by name.
SIZE_OBJECTIVE = "least-squares-size"
DOF_NAMES = ("tx", "ty", "tz", "rx", "ry", "rz")
COVARIANCE_LEAST_SQUARES = "weighted least squares"
COVARIANCE_OF_LEAST_SQUARES = ("weighted least squares of the same free degrees of freedom at "
                               "this pose (not the Chebyshev estimator's own scatter)")


# ---------------------------------------------------------------- degrees of freedom

@dataclass(frozen=True)
class FreeDOF:
    names: tuple          # as given, e.g. ('tx', 'ty', 'r_stacking')
    basis: np.ndarray     # (6, k): column j is the twist (t, w) of a unit parameter j

    @property
    def size(self):
        return self.basis.shape[1]


def free_dof(names=DOF_NAMES, axes=None, option="--free"):
    """The free degrees of freedom named: tx ty tz (translations along the CAD axes, mm),
    rx ry rz (rotations about them, rad), and for a direction named in ``axes``
    ({name: 3-vector}) t_<name> (translation along it) and r_<name> (rotation about it)."""
    axes = {} if axes is None else axes
    names = tuple(names)
    if not names:
        raise InputError("%s: no degree of freedom named (use %s)" % (option, _known(axes)))
    columns = []
    for name in names:
        column = np.zeros(6)
        if name in DOF_NAMES:
            column[DOF_NAMES.index(name)] = 1.0
        else:
            match = re.fullmatch(r"([tr])_(\w+)", name)
            if match is None or match.group(2) not in axes:
                raise InputError("%s: unknown degree of freedom '%s' (use %s)"
                                 % (option, name, _known(axes)))
            direction = np.asarray(axes[match.group(2)], dtype=float)
            norm = np.linalg.norm(direction) if direction.shape == (3,) else 0.0
            if not np.isfinite(norm) or norm == 0.0:
                raise InputError("%s: axis '%s' is not a non-zero 3-vector"
                                 % (option, match.group(2)))
            offset = 0 if match.group(1) == "t" else 3
            column[offset:offset + 3] = direction / norm
        columns.append(column)
    if len(set(names)) != len(names):
        raise InputError("%s: a degree of freedom is named twice in %s" % (option, ",".join(names)))
    basis = np.array(columns).T
    if np.linalg.matrix_rank(basis, tol=1e-9) < len(names):
        raise InputError("%s: %s are not independent (a direction is named twice)"
                         % (option, ",".join(names)))
    return FreeDOF(names, basis)


def in_plane_free(normal, chord_dir):
    """The three in-plane degrees of freedom of a section fit (2D, in the plane of unit normal
    ``normal``): translations along the chord and across it, rotation about the normal (with
    the fit's centre in the plane, a rotation in the plane). The twist stays in their span,
    so the points stay in their plane."""
    normal = np.asarray(normal, dtype=float)
    chord = np.asarray(chord_dir, dtype=float)
    chord = chord - (chord @ normal) / (normal @ normal) * normal
    cross = np.cross(normal, chord)
    return free_dof(("t_chord", "t_cross", "r_normal"),
                    {"chord": chord, "cross": cross, "normal": normal}, option="section fit")


def _known(axes):
    named = ", ".join("t_%s/r_%s" % (a, a) for a in sorted(axes))
    return ", ".join(DOF_NAMES) + (", " + named if named else "")


def parse_free(text, axes=None, option="--free"):
    """FreeDOF of a comma-separated list such as 'tx,ty,rz' or 'r_stacking' (see free_dof);
    'all' is the six."""
    tokens = [t.strip() for t in str(text).split(",")]
    if tokens == ["all"]:
        tokens = list(DOF_NAMES)
    if any(not t for t in tokens):
        raise InputError("%s: empty entry in '%s' (use a comma-separated list such as tx,ty,rz)"
                         % (option, text))
    return free_dof(tokens, axes, option)


def parse_zone_weights(text, zones=None, option="--weights-by-zone"):
    """{zone: weight} of 'LE=2,TE=2,suction=1,pressure=1'. Weights are finite and >= 0 (0
    leaves a zone out of the fit); a zone not named keeps weight 1 (per_zone).
    ``zones``: the labels allowed (e.g. inspection.sections.ZONES), or None for any."""
    weights = {}
    for entry in str(text).split(","):
        name, sep, value = (part.strip() for part in entry.partition("="))
        if not sep or not name:
            raise InputError("%s: '%s' is not zone=weight (e.g. LE=2,TE=2,suction=1,pressure=1)"
                             % (option, entry.strip()))
        if zones is not None and name not in zones:
            raise InputError("%s: unknown zone '%s' (zones: %s)" % (option, name, ", ".join(zones)))
        if name in weights:
            raise InputError("%s: zone '%s' is given twice" % (option, name))
        try:
            weight = float(value)
        except ValueError:
            raise InputError("%s: weight of %s is '%s', not a number" % (option, name, value))
        if not np.isfinite(weight) or weight < 0:
            raise InputError("%s: weight of %s is %s; weights are finite and >= 0"
                             % (option, name, value))
        weights[name] = weight
    return weights


def per_zone(labels, values, default=1.0):
    """(N,) value of each point from its zone label: region weights (parse_zone_weights) or a
    tolerance limit per zone; labels not in ``values`` (and points outside every zone, label
    '') get ``default``."""
    labels = np.asarray(labels, dtype=object)
    out = np.full(len(labels), float(default))
    for name, value in values.items():
        out[labels == name] = value
    return out


# ---------------------------------------------------------------- pose and Jacobian

def left_jacobian(w):
    """J_l(w) of SO(3): R(w + dw) = R(J_l(w) dw) R(w) to first order."""
    w = np.asarray(w, dtype=float)
    angle = np.linalg.norm(w)
    K = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    if angle < 1e-6:
        return np.eye(3) + 0.5 * K + K @ K / 6.0
    return (np.eye(3) + (1.0 - np.cos(angle)) / angle ** 2 * K
            + (angle - np.sin(angle)) / angle ** 3 * K @ K)


def pose_from_twist(init, center, twist):
    """T(xi) = G(xi) init with G: x -> c + R(w) (x - c) + t (module docstring)."""
    twist = np.asarray(twist, dtype=float)
    center = np.asarray(center, dtype=float)
    R = rotation_from_vector(twist[3:])
    return make_transform(R, center + twist[:3] - R @ center) @ np.asarray(init, dtype=float)


class _Problem:
    """The points at the start pose, the centre, the free basis and the parameter scaling, and
    the exact residuals and Jacobian at any parameter vector."""

    def __init__(self, points, closest_fn, init, weights, free, center):
        points = np.asarray(points, dtype=float)
        if points.ndim != 2 or points.shape[1] != 3:
            raise InputError("fit: points must have shape (N, 3), got %s" % (points.shape,))
        w = np.asarray(weights, dtype=float)
        if w.shape != (len(points),) or not np.all(np.isfinite(w)) or np.any(w < 0):
            raise InputError("fit: weights must be finite, >= 0 and one per point")
        self.free = free_dof() if free is None else free
        self.inlier = w > 0
        if np.count_nonzero(self.inlier) <= self.free.size:
            raise InputError("fit: %d points of positive weight, more than %d needed"
                             % (np.count_nonzero(self.inlier), self.free.size))
        self.init = np.array(init, dtype=float)
        self.start = points @ self.init[:3, :3].T + self.init[:3, 3]
        self.center = (w @ self.start / w.sum() if center is None
                       else np.asarray(center, dtype=float))
        self.weights = w
        self.closest_fn = closest_fn
        # Rotations scaled by the cloud's radius about the centre, so every parameter is in mm
        # of motion at the points' extremes: the linear programmes' trust box and the step
        # tolerance mean the same for translations and rotations.
        radius = max(float(np.max(np.linalg.norm(self.start - self.center, axis=1))), 1.0)
        rotational = np.any(self.free.basis[3:] != 0, axis=0)
        self.scale = np.where(rotational, radius, 1.0)

    def twist(self, theta):
        return self.free.basis @ (np.asarray(theta) / self.scale)

    def transform(self, theta):
        return pose_from_twist(self.init, self.center, self.twist(theta))

    def evaluate(self, theta, known=None):
        """(distances (N,), Jacobian (N, k) in scaled parameters, normals) at theta; ``known``:
        (distances, normals) already evaluated there, to save the closest-point call."""
        xi = self.twist(theta)
        R = rotation_from_vector(xi[3:])
        arm = (self.start - self.center) @ R.T        # R (x0 - c)
        if known is None:
            _, normals, distances = self.closest_fn(self.center + arm + xi[:3])
        else:
            distances, normals = (np.asarray(a, dtype=float) for a in known)
            if distances.shape != (len(arm),) or normals.shape != arm.shape:
                raise InputError("fit: at_init must be (distances (N,), normals (N, 3))")
        J6 = np.hstack([normals, np.cross(arm, normals) @ left_jacobian(xi[3:])])
        return np.asarray(distances, dtype=float), J6 @ self.free.basis / self.scale, normals

    def covariance(self, J, distances, multipliers):
        """6x6 covariance of the module docstring (inf when the points do not fix the free
        degrees of freedom); (6 + e)x(6 + e) when J has e columns after the pose's (the size
        offset, in mm, whose rows and columns come last)."""
        keep = self.inlier
        n, k = int(np.count_nonzero(keep)), J.shape[1]
        extra = k - self.free.size
        full = 6 + extra
        if n <= k:
            return np.full((full, full), np.inf)
        b, z, Jk, r = self.weights[keep], multipliers[keep], J[keep], distances[keep]
        H = (Jk * (b * z)[:, None]).T @ Jk
        d = np.sqrt(np.diag(H))
        if np.any(d == 0) or np.linalg.cond(H / np.outer(d, d)) > 1e12:
            return np.full((full, full), np.inf)
        s2 = float(np.sum(b * r ** 2)) / (n - k)
        Hinv = np.linalg.inv(H)
        meat = (Jk * (b * z ** 2)[:, None]).T @ Jk
        unscale = np.zeros((full, k))                 # d (xi, s) / d (theta_scaled, s)
        unscale[:6, :self.free.size] = self.free.basis / self.scale
        unscale[6:, self.free.size:] = np.eye(extra)
        return unscale @ (s2 * Hinv @ meat @ Hinv) @ unscale.T


# ---------------------------------------------------------------- results and options

@dataclass
class FitOptions:
    max_iter: int = 100           # closest-point evaluations (Gauss-Newton converges only
                                  # linearly when locked DOFs leave large residuals)
    step_tol_mm: float = 1e-9     # a step moving no point more than this has converged
    gain_tol_mm: float = 1e-9     # Chebyshev: a predicted gain below this has converged
    exchange_rows: int = 50       # constraints added to the linear programme per exchange
    lp_tol_mm: float = 1e-10      # a constraint violated by less is satisfied
    step_penalty: float = 1e-6    # margin (mm) traded per mm of step (see _max_min_step)


@dataclass
class FitResult:
    objective: str                # one of OBJECTIVES
    transform: np.ndarray         # (4,4) measured -> CAD
    distances: np.ndarray         # (N,) signed deviations of every point at `transform`
    inlier: np.ndarray            # (N,) bool: the points the fit judged (weight > 0)
    free: tuple                   # names of the free degrees of freedom
    twist: np.ndarray             # (6,) (t mm, w rad) of transform relative to init, about center
    center: np.ndarray            # (3,) CAD frame
    max_abs_deviation: float      # largest |d| of the inliers, mm
    rms: float                    # RMS of the inliers' d, mm
    iterations: int               # closest-point evaluations
    converged: bool
    covariance: np.ndarray        # (6,6) about center (see the module docstring)
    covariance_kind: str
    margin: Optional[float] = None     # tolerance: smallest slack (mm); < 0 is a violation
    fits: Optional[bool] = None        # tolerance: margin >= 0
    size: Optional[float] = None       # least squares with size: the offset s (mm)
    size_variance: Optional[float] = None   # its variance (mm^2; inf when not determined)

    @property
    def violation(self):
        """Tolerance fit: the largest violation of the best pose (0 when it fits), mm."""
        return None if self.margin is None else max(0.0, -self.margin)

    def to_json(self):
        """The fit as result.json records it (plain lists and numbers; infinities as None)."""
        def plain(a):
            return [None if not np.isfinite(v) else float(v) for v in np.ravel(a)]
        return {"objective": self.objective, "free": list(self.free),
                "measured_to_cad": np.asarray(self.transform).tolist(),
                "center_mm": plain(self.center),
                "twist": {"t_mm": plain(self.twist[:3]), "w_rad": plain(self.twist[3:])},
                "max_abs_deviation_mm": self.max_abs_deviation, "rms_mm": self.rms,
                "n_inliers": int(np.count_nonzero(self.inlier)),
                "iterations": self.iterations, "converged": self.converged,
                "covariance": np.reshape(plain(self.covariance), (6, 6)).tolist(),
                "covariance_kind": self.covariance_kind, "margin_mm": self.margin,
                "fits": self.fits, "violation_mm": self.violation,
                **({} if self.size is None else {
                    "size_mm": float(self.size),
                    "size_sigma_mm": (float(np.sqrt(self.size_variance))
                                      if np.isfinite(self.size_variance) else None)})}


def _result(problem, objective, theta, distances, J, multipliers, iterations, converged,
            kind, margin=None, size=None):
    keep = problem.inlier
    d = distances[keep]
    if size is not None:
        # The covariance over pose and size (J's last column is the offset's, -1): its
        # residuals are d - s.
        full = problem.covariance(J, distances - size, multipliers)
        covariance, size_variance = full[:6, :6], float(full[6, 6])
    return FitResult(
        objective=objective, transform=problem.transform(theta), distances=distances,
        inlier=keep.copy(), free=problem.free.names, twist=problem.twist(theta),
        center=problem.center.copy(), max_abs_deviation=float(np.max(np.abs(d))),
        rms=float(np.sqrt(np.mean(d ** 2))), iterations=iterations, converged=converged,
        covariance=(problem.covariance(J, distances, multipliers) if size is None
                    else covariance), covariance_kind=kind,
        margin=None if margin is None else float(margin),
        fits=None if margin is None else bool(margin >= 0),
        size=None if size is None else float(size),
        size_variance=None if size is None else size_variance)


# ---------------------------------------------------------------- least squares

def least_squares_fit(points, closest_fn, init, weights, free=None, multipliers=None,
                      center=None, options=None, at_init=None, size=False):
    """min sum w z d^2 over the free degrees of freedom (FreeDOF; None = all six), z the
    region multipliers (per_zone; None = 1). Gauss-Newton on the exact Jacobian,
    halving a step that raises the objective. ``at_init``: (distances, normals) of the points
    at ``init`` when the caller has them (ICPResult.distances and the normals), which saves a
    closest-point evaluation; likewise for the other fits. ``size``: fit a uniform normal
    offset s as well, min sum w z (d - s)^2 (SIZE_OBJECTIVE; FitResult.size)."""
    options = options or FitOptions()
    problem = _Problem(points, closest_fn, init, weights, free, center)
    z = (np.ones(len(problem.weights)) if multipliers is None
         else np.asarray(multipliers, dtype=float))
    if z.shape != problem.weights.shape or not np.all(np.isfinite(z)) or np.any(z < 0):
        raise InputError("fit: region multipliers must be finite, >= 0 and one per point")
    w = np.where(problem.inlier, problem.weights * z, 0.0)
    k = problem.free.size + int(bool(size))
    if np.count_nonzero(w) <= k:
        raise InputError("fit: the region weights leave %d points, more than %d needed"
                         % (np.count_nonzero(w), k))
    sw = np.sqrt(w[w > 0])

    def evaluate(params, known=None):
        distances, J, _ = problem.evaluate(params[:problem.free.size], known)
        if size:
            J = np.hstack([J, -np.ones((len(J), 1))])
            return distances, J, distances - params[-1]
        return distances, J, distances

    params = np.zeros(k)
    distances, J, residual = evaluate(params, at_init)
    cost = float(np.sum(w * residual ** 2))
    iterations, converged = int(at_init is None), False
    while iterations < options.max_iter:
        step = np.linalg.lstsq(J[w > 0] * sw[:, None], -residual[w > 0] * sw, rcond=1e-12)[0]
        if np.abs(step).sum() < options.step_tol_mm:
            converged = True
            break
        while iterations < options.max_iter:
            trial = params + step
            d_trial, J_trial, r_trial = evaluate(trial)
            iterations += 1
            trial_cost = float(np.sum(w * r_trial ** 2))
            if trial_cost <= cost or np.abs(step).sum() < options.step_tol_mm:
                params, distances, J, residual, cost = trial, d_trial, J_trial, r_trial, \
                    trial_cost
                break
            step = 0.5 * step
    theta = params[:problem.free.size]
    if size:
        return _result(problem, SIZE_OBJECTIVE, theta, distances, J, z, iterations, converged,
                       COVARIANCE_LEAST_SQUARES, size=params[-1])
    return _result(problem, "least-squares", theta, distances, J, z, iterations, converged,
                   COVARIANCE_LEAST_SQUARES)


def size_take_up(points, normals, weights, center, free=None):
    """(6,) r = (t mm, w rad) per mm of uniform normal offset: the rigid motion about
    ``center`` a plain weighted least-squares fit makes to take up a part uniformly oversize
    by 1 mm (to first order), min_r sum w_i (1 - J_i r)^2, J_i = [n_i, (p_i - c) x n_i].
    For a size error delta the plain fit's twist (FitResult.twist, moving point p by
    t + w x (p - c)) is -delta r: it moves the points back by what a rigid motion can take
    up, and each deviation reads delta (1 - J_i r) instead of delta (as core.bias_take_up's
    r for a reading bias, with beta_i = 1). ``free``: the fit's FreeDOF (None: all six); r
    then lies in their span."""
    points = np.asarray(points, dtype=float)
    normals = np.asarray(normals, dtype=float)
    w = np.asarray(weights, dtype=float)
    keep = (w > 0) & np.all(np.isfinite(points), axis=1) & np.all(np.isfinite(normals), axis=1)
    if not np.any(keep):
        return np.zeros(6)
    J = np.hstack([normals[keep], np.cross(points[keep] - np.asarray(center, float),
                                           normals[keep])])
    basis = free_dof().basis if free is None else free.basis
    JB = J @ basis
    JW = JB.T * w[keep]
    return basis @ np.linalg.lstsq(JW @ JB, JW @ np.ones(int(keep.sum())), rcond=1e-12)[0]


# ---------------------------------------------------------------- Chebyshev fits

def _slack(distances, lower, upper):
    return np.minimum(distances - lower, upper - distances)


def _max_min_step(J, distances, lower, upper, radius, options):
    """The step delta (|delta_j| <= radius) maximising min_i of the linearised slacks
    min(d_i + J_i delta - l_i, u_i - d_i - J_i delta), and that minimum.

    Variables (delta+, delta-, m), delta = delta+ - delta-, rows
        -J_i delta + m <= d_i - l_i   and   J_i delta + m <= u_i - d_i,
    objective  -m + step_penalty * sum |delta|: where the optimum is not unique (a direction
    no binding point constrains, e.g. a slide along a surface that does not fix it) the
    smallest step is taken instead of an arbitrary corner of the trust box; the penalty costs
    at most step_penalty * |delta| of margin.
    Solved on a working set of rows, starting from the most binding ones, adding the most
    violated rows of the rest until the step violates none.
    """
    n, k = J.shape
    ones = np.ones((n, 1))
    A = np.vstack([np.hstack([-J, J, ones]), np.hstack([J, -J, ones])])
    b = np.concatenate([distances - lower, upper - distances])
    working = np.argsort(b)[:max(options.exchange_rows, 4 * (k + 1))]
    cost = np.r_[np.full(2 * k, options.step_penalty), -1.0]
    bounds = [(0.0, radius)] * (2 * k) + [(None, None)]
    while True:
        solution = linprog(cost, A_ub=A[working], b_ub=b[working], bounds=bounds,
                           method="highs-ds",
                           options={"primal_feasibility_tolerance": 1e-10,
                                    "dual_feasibility_tolerance": 1e-10})
        if solution.status != 0:
            raise RuntimeError("fit: linear programme failed: %s" % solution.message)
        x = solution.x
        excess = A @ x - b
        violated = np.flatnonzero(excess > options.lp_tol_mm)
        if not len(violated):
            return x[:k] - x[k:2 * k], x[2 * k]
        worst = violated[np.argsort(-excess[violated])][:options.exchange_rows]
        working = np.union1d(working, worst)


def _chebyshev_fit(problem, objective, lower, upper, options, at_init):
    keep = problem.inlier
    lo, hi = lower[keep], upper[keep]
    theta = np.zeros(problem.free.size)
    distances, J, _ = problem.evaluate(theta, at_init)
    margin = float(np.min(_slack(distances[keep], lo, hi)))
    # Trust box (mm at the points' extremes): the fit's moves are of the size of the
    # deviations themselves.
    radius = max(float(np.max(np.abs(distances[keep]))), 1e3 * options.step_tol_mm)
    iterations, converged = int(at_init is None), False
    while iterations < options.max_iter:
        step, predicted = _max_min_step(J[keep], distances[keep], lo, hi, radius, options)
        gain = predicted - margin
        if gain < options.gain_tol_mm or np.abs(step).sum() < options.step_tol_mm:
            converged = True
            break
        trial = theta + step
        d_trial, J_trial, _ = problem.evaluate(trial)
        iterations += 1
        trial_margin = float(np.min(_slack(d_trial[keep], lo, hi)))
        ratio = (trial_margin - margin) / gain
        if ratio > 0:
            theta, distances, J, margin = trial, d_trial, J_trial, trial_margin
            if ratio > 0.75 and np.max(np.abs(step)) > 0.99 * radius:
                radius *= 2.0
        if ratio < 0.25:
            radius = 0.25 * float(np.max(np.abs(step)))
            if radius < options.step_tol_mm:
                break   # the linearisation predicts a gain no small step delivers: stalled
    return _result(problem, objective, theta, distances, J, np.ones(len(distances)),
                   iterations, converged, COVARIANCE_OF_LEAST_SQUARES,
                   margin if objective == "tolerance" else None)


def minimax_fit(points, closest_fn, init, weights, free=None, center=None, options=None,
                at_init=None):
    """min over the free degrees of freedom of max |d| of the inliers (weight > 0)."""
    problem = _Problem(points, closest_fn, init, weights, free, center)
    zero = np.zeros(len(problem.weights))
    return _chebyshev_fit(problem, "minimax", zero, zero, options or FitOptions(), at_init)


def tolerance_fit(points, closest_fn, init, weights, lower, upper, free=None, center=None,
                  options=None, at_init=None):
    """The pose of the largest margin in the tolerance zones [lower_i, upper_i] (mm, one per
    point or one for all), or of the least largest violation when none fits (module
    docstring); FitResult.margin, .fits and .violation say which."""
    problem = _Problem(points, closest_fn, init, weights, free, center)
    n = len(problem.weights)
    lower = np.broadcast_to(np.asarray(lower, dtype=float), (n,)).copy()
    upper = np.broadcast_to(np.asarray(upper, dtype=float), (n,)).copy()
    keep = problem.inlier
    if not (np.all(np.isfinite(lower[keep])) and np.all(np.isfinite(upper[keep]))):
        raise InputError("fit: every judged point needs a finite lower and upper tolerance")
    if np.any(lower[keep] > upper[keep]):
        raise InputError("fit: a tolerance zone has its lower limit above its upper limit")
    return _chebyshev_fit(problem, "tolerance", lower, upper, options or FitOptions(), at_init)


def fit(objective, points, closest_fn, init, weights, free=None, center=None, multipliers=None,
        lower=None, upper=None, options=None, at_init=None):
    """The fit named by ``objective`` (one of OBJECTIVES or SIZE_OBJECTIVE, as ``--fit``
    names it); region multipliers belong to the least-squares fits, tolerance zones to the
    tolerance fit."""
    if objective not in OBJECTIVES + (SIZE_OBJECTIVE,):
        raise InputError("--fit: unknown objective '%s' (use %s)"
                         % (objective, ", ".join(OBJECTIVES + (SIZE_OBJECTIVE,))))
    least_squares = objective in ("least-squares", SIZE_OBJECTIVE)
    if multipliers is not None and not least_squares:
        raise InputError("--weights-by-zone: region weights apply to the least-squares fit "
                         "only, not to %s" % objective)
    if (lower is None or upper is None) == (objective == "tolerance"):
        raise InputError("--fit %s: tolerance zones are %s" % (
            objective, "needed" if objective == "tolerance" else "for --fit tolerance only"))
    common = dict(free=free, center=center, options=options, at_init=at_init)
    if least_squares:
        return least_squares_fit(points, closest_fn, init, weights, multipliers=multipliers,
                                 size=objective == SIZE_OBJECTIVE, **common)
    if objective == "minimax":
        return minimax_fit(points, closest_fn, init, weights, **common)
    return tolerance_fit(points, closest_fn, init, weights, lower, upper, **common)
