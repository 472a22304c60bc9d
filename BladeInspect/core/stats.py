"""Statistics of signed deviations: the figures of the paper's Table 3 and Fig. 12."""

import numpy as np

from .contracts import PROFILE_TOLERANCE_MM
from .errors import InputError


def tolerance_bands(tolerance):
    """Band edges for a symmetric tolerance t: +-t, +-1.5t, +-2t (Table 3's bands for t = 0.04)."""
    try:
        t = float(tolerance)
    except (TypeError, ValueError):
        raise InputError("tolerance: %r is not a number" % (tolerance,))
    if not np.isfinite(t) or t <= 0:
        raise InputError("tolerance: must be a positive number of millimetres, got %r"
                         % (tolerance,))
    return (-2.0 * t, -1.5 * t, -t, t, 1.5 * t, 2.0 * t)


# Paper Table 3: < -0.08, -0.08..-0.06, -0.06..-0.04, -0.04..0.04, 0.04..0.06, 0.06..0.08, > 0.08
DEFAULT_BAND_EDGES = tolerance_bands(PROFILE_TOLERANCE_MM)


def _check_edges(band_edges):
    try:
        edges = np.asarray(band_edges, dtype=float).ravel()
    except (TypeError, ValueError):
        raise InputError("band edges: %r are not numbers" % (band_edges,))
    if len(edges) == 0 or not np.all(np.isfinite(edges)) or np.any(np.diff(edges) <= 0):
        raise InputError("band edges: need finite, strictly increasing values, got %s"
                         % list(band_edges))
    return edges


def deviation_statistics(dev, band_edges=DEFAULT_BAND_EDGES):
    """Summary of signed deviations (mm) as plain, JSON-ready Python values.

    sigma is the standard deviation about the mean (population, ddof 0), and
    pct_within_k_sigma counts |d - mean| <= k sigma. Histogram bands are lo <= d < hi between
    consecutive edges, plus an open band below the first edge (lo None) and one from the last
    edge up (hi None), so every deviation falls in exactly one band.
    """
    d = np.asarray(dev, dtype=float).ravel()
    edges = _check_edges(band_edges)
    if len(d) == 0:
        raise InputError("deviations: there are none to summarise")
    bad = np.count_nonzero(~np.isfinite(d))
    if bad:
        raise InputError("deviations: %d of %d values are not finite" % (bad, len(d)))
    n = len(d)
    mean = float(d.mean())
    std = float(d.std())
    spread = np.abs(d - mean)
    # searchsorted 'right': a deviation equal to an edge belongs to the band starting there.
    counts = np.bincount(np.searchsorted(edges, d, side="right"), minlength=len(edges) + 1)
    lows = [None] + [float(e) for e in edges]
    highs = [float(e) for e in edges] + [None]
    return {
        "n": n,
        "min": float(d.min()),
        "max": float(d.max()),
        "mean": mean,
        "rms": float(np.sqrt(np.mean(d ** 2))),
        "std": std,
        "pct_within_1sigma": 100.0 * np.count_nonzero(spread <= std) / n,
        "pct_within_3sigma": 100.0 * np.count_nonzero(spread <= 3.0 * std) / n,
        "histogram": [{"lo": lo, "hi": hi, "count": int(c), "pct": 100.0 * int(c) / n}
                      for lo, hi, c in zip(lows, highs, counts)],
    }
