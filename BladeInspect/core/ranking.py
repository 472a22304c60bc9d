"""One objective for ranking candidate poses, and the test of whether the best two differ.

Why this objective: a candidate judged by the residual of the points it keeps, or
by a median, can look better than the truth by explaining most of the part and rejecting the
rest - on a near-symmetric vane the half-turned pose fits both arcs and drops both edges. So
every candidate is judged on the same points (all of them), by the same loss, at the same
scale:

    L(T) = sum_i rho(u_i),  u_i = |d_i(T)| sqrt(max(a_i, 1/r^2)) / s

* rho is the M-estimator loss whose iteratively reweighted least-squares weight is exactly the
  fine ICP's robust weight (core.icp._taper): rho(u) = int_0^u w(t) t dt, i.e. u^2 / 2 up to
  k_full, then the biweight taper's integral, constant from k_zero on. So a candidate is
  ranked by the very objective the fine stage will minimise from it, and a point the fine
  stage would reject costs the most any point can cost: discarding a good point (u ~ 1, cost
  ~0.5) costs about rho(k_zero) - 0.5 ~ 6.8 instead. In likelihood terms rho is, up to a
  constant, the negative log-likelihood of a normal error of scale s with an explicit outlier
  term (a flat density reached at k_zero scales), which is what makes the test below Vuong's.
* a_i (SNR weight) and the floor r = max_noise_ratio are the ICP's own (core.icp).
* s is ONE scale for every candidate: the smallest of their robust noise estimates
  (1.4826 median |z|). At the true pose that is the sensor's noise; a wrong pose cannot make
  most residuals smaller than the noise, so the minimum is the noise whichever candidate is
  right, and no candidate can buy a smaller loss by widening or narrowing its own scale.

The ambiguity test (Vuong's closeness test for non-nested models): with per-point loss
differences delta_i = rho_rival,i - rho_best,i, the statistic z = sum(delta) / (sqrt(n) *
std(delta)) is standard normal when the two poses explain the data equally well. The best pose
is only called decided when z >= DECIDED_Z.
"""

from dataclasses import dataclass

import numpy as np

from .icp import MAD_TO_SIGMA, ICPOptions, snr_weights

# Vuong statistic above which the best candidate is taken as decided. Under exact equivalence
# z is the |N(0,1)| of the better of two: it exceeds 4 once in 16,000 registrations, so a
# symmetric part is almost never given a confident pose; a real difference between the poses
# grows z like the square root of the number of points that tell them apart (about 16 points
# well outside the noise give z = 4).
DECIDED_Z = 4.0


def robust_loss(u, options=None):
    """rho(u) of the module docstring for standardised residuals u (>= 0, inf allowed)."""
    options = options or ICPOptions()
    k1, k0 = options.k_full, options.k_zero
    width = k0 - k1
    u = np.abs(np.asarray(u, dtype=float))
    x = np.clip((u - k1) / width, 0.0, 1.0)
    core = 0.5 * np.minimum(u, k1) ** 2
    taper = (width * k1 * (x - 2.0 * x ** 3 / 3.0 + x ** 5 / 5.0)
             + width ** 2 * (x ** 2 / 2.0 - x ** 4 / 2.0 + x ** 6 / 6.0))
    return core + taper


def standardised(distances, snr, options=None):
    """|d_i| sqrt(max(a_i, 1/r^2)) in mm (before dividing by the common scale); inf where a
    distance is not finite."""
    options = options or ICPOptions()
    d = np.asarray(distances, dtype=float)
    a = snr_weights(snr, len(d))
    z = np.abs(d) * np.sqrt(np.maximum(a, options.max_noise_ratio ** -2))
    return np.where(np.isfinite(z), z, np.inf)


def noise_scale(z):
    """Robust noise estimate of one candidate's standardised residuals (mm)."""
    finite = z[np.isfinite(z)]
    return MAD_TO_SIGMA * float(np.median(finite)) if len(finite) else np.inf


@dataclass
class Comparison:
    difference: float        # sum of rho, rival minus best (>= 0 when best is the better)
    standard_error: float    # sqrt(n) * std of the per-point differences
    z: float                 # difference / standard_error (Vuong's statistic)
    decided: bool            # z >= DECIDED_Z


def compare(loss_best, loss_rival):
    """Vuong's test of the per-point losses of two poses on the same points."""
    delta = np.asarray(loss_rival, dtype=float) - np.asarray(loss_best, dtype=float)
    n = len(delta)
    difference = float(delta.sum())
    se = float(np.sqrt(n) * np.std(delta, ddof=1)) if n > 1 else 0.0
    # Identical per-point differences (no spread) are no evidence either way.
    z = difference / se if se > 0 else 0.0
    return Comparison(difference, se, float(z), bool(z >= DECIDED_Z))


def rank(standardised_residuals, options=None, min_scale=None):
    """The common scale and each candidate's per-point losses and total objective.

    standardised_residuals: list of (n,) arrays from ``standardised``, one per candidate, on the
    same points. Returns (scale_mm, losses list of (n,), objectives list of floats)."""
    options = options or ICPOptions()
    floor = options.min_scale if min_scale is None else min_scale
    scale = max(min(noise_scale(z) for z in standardised_residuals), floor)
    losses = [robust_loss(z / scale, options) for z in standardised_residuals]
    return scale, losses, [float(l.sum()) for l in losses]
