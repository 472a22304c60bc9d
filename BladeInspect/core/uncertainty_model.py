"""The error of a reported maximum of noisy readings (numpy only): the bias and scatter of
max_i |d_i| against the true max_i |t_i| when several readings compete for the maximum.

A worst deviation (a section's, the part's), a contour's form are maxima over points. When n
readings could be the largest, the reported one is the largest of their noisy readings: it is
biased upwards (by about the noise's own maximum: for many uniform readings of half-width a,
nearly a) and scatters less than one reading. What an ISO 14253-1 decision needs is the error
of the reported value against the true one, bias included.

Model (``max_error``): the competing readings are those within ``competing_sigmas`` combined
noise sigmas of the reported maximum (any of them could be the true largest); their true values
are taken as one common level T on the measured side of each (a plateau: the case of the most
competitors, so the largest bias; a peaked true field gives less), and T is the reported
maximum less the bias itself (a fixed point). The readings' noise is each one's own sigma in
the sensor's distribution (``unit_noise``: draws of unit variance, e.g. uniform, clipped
normal). The error's mean (the bias) and standard deviation come from ``draws`` seeded
samples of the competing readings; a lone competitor is a single reading (bias 0, its
sigma), in closed form. Errors common to the readings (``SharedTerm``: a reading bias the fit
left unevenly, the pose) are sampled with the noise where they move the competitors
differently, since the maximum then takes the largest push.

Where a selection has kept only readings measured at most a cut-off (a robust fit that gives a
defect's top no weight and keeps its flanks), the largest kept reading is a censored maximum
(``censored_max_error``): a reading that noise pushes above the cut-off is left out rather than
reported, and one whose true level lies above it is kept when its noise pulls it below. The
upward bias of max_error is then gone and the truth itself (the largest true level among the
kept readings) follows the noise; there the readings' own levels, not a plateau, decide. The
selection may be given as a replay of the fit's own tests (``kept``: core.icp.InlierCut), which
judge a reading by its neighbourhood's readings as well as its own.
"""

import numpy as np

COMPETING_SIGMAS = 2.0
DRAWS = 1000
_FIXED_POINT_ROUNDS = 4
_MAX_SAMPLES = 500_000
_MIN_DRAWS = 200
# A bound of the noise in sigmas when the caller gives none (uniform: sqrt 3; clipped normal
# at 3 sigma: about 3)
FOLD_SIGMAS = 4.0


def uniform_unit_noise(rng, shape):
    """Uniform draws of unit variance (half-width sqrt 3)."""
    return rng.uniform(-np.sqrt(3.0), np.sqrt(3.0), shape)


def competing(deviation, sigma, competing_sigmas=COMPETING_SIGMAS):
    """(index of the largest |deviation|, boolean mask of the readings competing with it)."""
    dev = np.abs(np.asarray(deviation, dtype=float))
    sigma = np.asarray(sigma, dtype=float)
    worst = int(np.argmax(dev))
    with np.errstate(invalid="ignore"):
        mask = dev >= dev[worst] - competing_sigmas * np.sqrt(sigma[worst] ** 2 + sigma ** 2)
    mask[worst] = True
    return worst, mask


class SharedTerm:
    """An error common to the readings (a reading bias, the pose): reading i moves by
    coefficients[i] . z, z one draw of ``sample(rng, draws) -> (draws, k)`` for all of them."""

    def __init__(self, name, coefficients, sample):
        self.name = name
        self.coefficients = np.asarray(coefficients, dtype=float)
        if self.coefficients.ndim == 1:
            self.coefficients = self.coefficients[:, None]
        self.sample = sample

    def take(self, index):
        """The same term over the readings ``index`` only (the same draws move them alike)."""
        return SharedTerm(self.name, self.coefficients[index], self.sample)

    def moves(self, z, index=slice(None)):
        """(draws, n) displacement of the readings ``index`` for the draws z."""
        return z @ self.coefficients[index].T


def max_error(deviation, sigma, unit_noise=uniform_unit_noise, shared=(),
              competing_sigmas=COMPETING_SIGMAS, draws=DRAWS, seed=0, equal_sigma_max=None,
              noise_bound_sigmas=FOLD_SIGMAS, bias_only=False):
    """The error of the reported max |deviation| as an estimate of the true largest
    |deviation| (module notes): (terms {name: mm}, bias, number of competing readings), the
    bias that of the noise and the sampled shared terms together.
    The terms' root sum of squares is the RMS error, bias included: "noise_mm" that of the
    noise alone, then each SharedTerm in ``shared`` that moves the competitors differently
    what it adds, sampled with the noise (its largest push is what the maximum takes). A
    shared term that moves every competitor alike moves the maximum rigidly and adds its
    own variance at the worst reading: it is left out of ``terms`` for the caller to add
    in closed form (as for a lone worst, n = 1). ``sigma``: each reading's noise 1 sigma along the deviation (mm).
    ``equal_sigma_max``: n -> (mean, sd) of the largest of n unit-variance draws in closed
    form, used instead of sampling the noise when the competitors share one sigma and their
    level lies clear of zero (beyond ``noise_bound_sigmas``, the largest a reading's noise can
    be in sigmas, where |level + noise| is level + noise).
    ``bias_only``: the bias alone is wanted (terms returned empty): of the sampled rounds only
    the last, noise and every varying term together, is run -- the bias is that round's; the
    draws are the same, so the bias is the full call's to the bit."""
    dev = np.asarray(deviation, dtype=float).reshape(-1)
    sigma = np.asarray(sigma, dtype=float).reshape(-1)
    rng = np.random.default_rng(seed)
    probe = [t.sample(rng, _MIN_DRAWS) for t in shared]
    # The competitors are those the noise could have ranked above the worst. A reading further
    # below that a shared term could push up is left out: its measured level already holds
    # this scan's push, and adding a fresh one to it would count that push twice.
    worst, mask = competing(dev, sigma, competing_sigmas)
    n = int(np.count_nonzero(mask))
    reported = abs(dev[worst])
    common = sigma[mask]
    # a term that moves all competitors alike in every probe draw (or not at all) is rigid
    varying = []
    for t, z in zip(shared, probe):
        moves = t.moves(z, mask)
        if np.ptp(moves, axis=1).max() > 1e-12 * max(np.abs(moves).max(), 1e-300):
            varying.append(t)
    terms = {}
    closed = (equal_sigma_max is not None and not varying
              and np.ptp(common) <= 1e-12 * common[0])
    if n == 1:
        terms["noise_mm"], bias = float(sigma[worst]), 0.0
    elif (closed and reported - common[0] * equal_sigma_max(n)[0]
          >= noise_bound_sigmas * common[0]):
        mean, sd = equal_sigma_max(n)
        bias = float(common[0] * mean)
        terms["noise_mm"] = float(common[0] * np.hypot(mean, sd))
    else:
        side = np.where(dev[mask] < 0, -1.0, 1.0)
        # fewer draws for many competitors (their maximum scatters little), a bounded array
        draws = int(np.clip(_MAX_SAMPLES // n, _MIN_DRAWS, draws))
        noise = unit_noise(rng, (draws, n)) * common
        pushes = [t.moves(t.sample(rng, draws), mask) for t in varying]
        total = 0.0
        for k in range(len(varying) if bias_only else 0, len(varying) + 1):
            moved = noise + sum(pushes[:k]) if k else noise
            # |side level + moved| = |level + side moved| (side is +-1: exact), and rounding
            # is monotone, so a row's largest |level + x| is the larger of level + max x and
            # -(level + min x): each round is two (draws,) sums, the same errors to the bit
            x = side * moved
            top, low = x.max(axis=1), x.min(axis=1)
            level = reported
            for _ in range(_FIXED_POINT_ROUNDS + 1):
                error = np.maximum(level + top, -(level + low)) - level
                if _ < _FIXED_POINT_ROUNDS:
                    level = max(reported - float(error.mean()), 0.0)
            rms = float(np.sqrt(np.mean(error ** 2)))
            name = "noise_mm" if k == 0 else varying[k - 1].name
            if not bias_only:
                terms[name] = float(np.sqrt(max(rms ** 2 - total ** 2, 0.0)))
            total = rms
            bias = float(error.mean())
    if bias_only:
        terms = {}
    return terms, bias, n


def censored_max_error(level, sigma, cutoff, unit_noise=uniform_unit_noise, shared=(),
                       draws=DRAWS, seed=0, kept=None, judged=None):
    """The error of the largest reading a selection kept, the selection keeping a reading
    only when its measured value is at most ``cutoff`` (module notes), or as ``kept`` decides:
    (terms {name: mm}, bias, number of readings judged). ``level``: the readings' true levels,
    signed so that the maximum is the largest (the caller turns the measured side up);
    ``sigma``: each one's noise 1 sigma. Each draw measures every reading afresh (noise in
    ``unit_noise``, and the ``shared`` terms' pushes), keeps some, and errs by the largest kept
    measured value less the largest kept true level; a draw that keeps none is not counted.
    ``judged``: the positions of the readings the maximum is over (default all; the others
    only take part in ``kept``); ``kept(measured (draws, n)) -> (draws, len(judged)) bool``,
    default measured <= cutoff (a selection by neighbourhoods reads the others).
    Terms as max_error's: "noise_mm" that of the noise alone, then what each shared term adds
    (root sum of squares: the RMS error, bias included)."""
    level = np.asarray(level, dtype=float).reshape(-1)
    sigma = np.asarray(sigma, dtype=float).reshape(-1)
    n = len(level)
    judged = np.arange(n) if judged is None else np.asarray(judged, dtype=int)
    if kept is None:
        kept = (lambda measured: measured[:, judged] <= cutoff)
    rng = np.random.default_rng(seed)
    draws = int(np.clip(_MAX_SAMPLES // max(n, 1), _MIN_DRAWS, draws))
    measured = level + unit_noise(rng, (draws, n)) * sigma
    terms, total, bias = {}, 0.0, 0.0
    for term in [None] + list(shared):
        if term is not None:
            measured = measured + term.moves(term.sample(rng, draws))
        keep = kept(measured)
        some = keep.any(axis=1)
        keep = keep[some]
        error = (np.where(keep, measured[some][:, judged], -np.inf).max(axis=1)
                 - np.where(keep, level[judged], -np.inf).max(axis=1))
        rms = float(np.sqrt(np.mean(error ** 2))) if len(error) else float("inf")
        terms["noise_mm" if term is None else term.name] = float(
            np.sqrt(max(rms ** 2 - total ** 2, 0.0)))
        total = rms
        bias = float(error.mean()) if len(error) else float("nan")
    return terms, bias, len(judged)
