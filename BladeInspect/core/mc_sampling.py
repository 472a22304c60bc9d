"""Sampling a Monte Carlo of the measurement chain with few trials (numpy only;
bench/bench_uncertainty_mc.py): the systematic term drawn stratified, and each value's
scatter with that term's share taken from its known distribution.

A whole-chain trial costs seconds, so the Monte Carlo that validates U runs 8-16 trials. The
sensor's stated accuracy enters as one reading bias per trial, uniform in +-accuracy, and for
many characteristics (a thickness, a chord, an area) it is the largest term: their scatter
over the trials is then that of 8-16 draws of one uniform variable, whose sample standard
deviation scatters by about 20 % at 8 trials, and a cluster of draws (Rotor 67, seed 2026: 6
of 8 within -5.7..-4.4 um of a +-6 um range) reads as a tight mode off the truth, the rest then
cut as outliers. Two standard variance reductions, neither of which changes what is sampled:

- ``stratified_uniform``: trial k's bias from its own one of n equal strata of the range, in
  random order (Latin hypercube sampling): each draw is still uniform over the range;
- ``scatter_and_rms``: the error split into the part that follows the trial's bias (the least-
  squares line over the trials) and a residual uncorrelated with it, var = c^2 var(b) +
  var(r) for any shape of the response; var(b) is known, not estimated (a control variate).
"""

import numpy as np


def stratified_uniform(rng, n, half_width):
    """(n,) draws uniform in +-half_width, one from each of n equal strata in random order."""
    strata = rng.permutation(n) + rng.uniform(0.0, 1.0, n)
    return half_width * (2.0 * strata / n - 1.0)


def scatter_and_rms(error, bias, bias_sd):
    """(1 sd, RMS) of a value's ``error`` against its truth over the trials, the share that
    follows the trials' drawn ``bias`` (mean zero, standard deviation ``bias_sd``) from that
    known spread: sd^2 = c^2 bias_sd^2 + s_r^2 with c the least-squares slope of the error on
    the bias and s_r^2 the residual variance (n - 2 degrees of freedom); the mean square
    error c^2 bias_sd^2 + (mean(error - c b))^2 + s_r^2 (n - 1) / n. Without a bias (None) or
    with fewer than 4 trials, the plain sample figures."""
    err = np.asarray(error, dtype=float)
    n = len(err)
    if bias is None or n < 4:
        return float(np.std(err, ddof=1)), float(np.sqrt(np.mean(err ** 2)))
    b = np.asarray(bias, dtype=float)
    A = np.column_stack([np.ones(n), b - b.mean()])
    (alpha, c), *_ = np.linalg.lstsq(A, err, rcond=None)
    resid = err - A @ np.array([alpha, c])
    var_r = float(resid @ resid) / (n - 2)
    mean_r = float(np.mean(err - c * b))
    sd = np.sqrt(c * c * bias_sd ** 2 + var_r)
    rms = np.sqrt(c * c * bias_sd ** 2 + mean_r ** 2 + var_r * (n - 1) / n)
    return float(sd), float(rms)
