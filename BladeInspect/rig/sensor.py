"""The conoscopic point sensor as a statistical model (paper Table 1, docs/contracts.md "The sensor
and its noise"): which readings exist, their SNR, their noise and their gross errors.

One noise model serves measurement and registration: a reading's standard deviation is
sigma(SNR) = sigma_ref * sqrt(SNR_ref / SNR) along the beam, so 1/sigma^2 is proportional to SNR.
Along the surface normal, which the fit's residual measures, that noise is sigma(SNR) cos(theta)
at incidence theta, so the maximum-likelihood weights are 1 / (sigma(SNR) cos theta)^2
(core.weights, `--weights sensor`), not the paper's SNR-linear ones (`--weights snr`).
"""

from dataclasses import asdict, dataclass

import numpy as np
from scipy.stats import norm

from ..core.errors import InputError

NOISE_KINDS = ("uniform", "normal")
# The normal option is clipped at this many sigma: the paper's Fig. 8 figures fit a normal error
# of sigma = accuracy / 3 clipped at +-accuracy (docs/contracts.md "The sensor and its noise").
NORMAL_CLIP_SIGMAS = 3.0


def clipped_normal_std(c):
    """Standard deviation of a unit normal clipped (not truncated) at +-c: the tails pile up
    at +-c, so the variance is the truncated part plus c^2 times the tail mass."""
    tail = norm.sf(c)
    inner = (2.0 * norm.cdf(c) - 1.0) - 2.0 * c * norm.pdf(c)
    return float(np.sqrt(inner + 2.0 * tail * c * c))


@dataclass
class SensorModel:
    """ConoProbe Mark 10 with the 50 mm lens by default. Lengths in mm, angles in degrees.

    SNR (0..100) at true distance d and incidence theta (angle between beam and surface normal):
    snr_max * cos(theta)**angle_exponent * (1 - range_falloff * ((d - standoff)/half_range)**2),
    so it is best head-on at the centre of the range and falls towards the range ends and grazing
    incidence. No reading outside the working range, beyond coverage/2 incidence or below
    snr_min. ``accuracy`` is the error bound at SNR_ref (uniform: half-width; normal: 3 sigma,
    clipped there); ``repeatability`` and ``spot`` are the data sheet's and are not simulated
    (every pass draws fresh noise of the accuracy's size, the pessimistic reading of the sheet).
    """
    standoff: float = 44.0
    half_range: float = 8.0
    accuracy: float = 0.006
    repeatability: float = 0.001
    spot: float = 0.026
    rate_hz: float = 9000.0
    coverage_deg: float = 170.0
    resolution: float = 1e-4
    noise: str = "uniform"
    snr_max: float = 100.0
    snr_ref: float = 100.0
    snr_min: float = 3.0
    angle_exponent: float = 1.0
    range_falloff: float = 0.5
    # Gross errors (0.1-0.5 mm, either sign) appear below gross_snr, with a probability rising
    # linearly to gross_probability at snr_min: grazing spots on the edges give most of them.
    gross_snr: float = 25.0
    gross_probability: float = 0.1
    gross_magnitude: tuple = (0.1, 0.5)

    def __post_init__(self):
        if self.noise not in NOISE_KINDS:
            raise InputError("--noise: expected uniform or normal, got %r" % (self.noise,))
        for name in ("standoff", "half_range", "accuracy", "rate_hz", "coverage_deg",
                     "snr_max", "snr_ref", "snr_min"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise InputError("sensor %s: must be a positive number, got %r" % (name, value))
        if not 0 < self.coverage_deg <= 180:
            raise InputError("sensor coverage_deg: must be in (0, 180], got %r"
                             % (self.coverage_deg,))
        if not 0 <= self.gross_probability <= 1:
            raise InputError("sensor gross_probability: must be in [0, 1], got %r"
                             % (self.gross_probability,))
        self.gross_magnitude = tuple(float(v) for v in self.gross_magnitude)

    @property
    def working_range(self):
        """(near, far) distances along the beam that give a reading."""
        return self.standoff - self.half_range, self.standoff + self.half_range

    @property
    def max_incidence_rad(self):
        return np.radians(0.5 * self.coverage_deg)

    @property
    def sigma_ref(self):
        """Standard deviation of the noise at SNR_ref."""
        if self.noise == "uniform":
            return self.accuracy / np.sqrt(3.0)
        return self.accuracy / NORMAL_CLIP_SIGMAS * clipped_normal_std(NORMAL_CLIP_SIGMAS)

    def snr(self, true_distance, incidence_rad):
        """Noise-free SNR of readings at these distances and incidences; 0 where none exists."""
        d = np.asarray(true_distance, dtype=float)
        inc = np.abs(np.asarray(incidence_rad, dtype=float))
        with np.errstate(invalid="ignore"):
            rel = (d - self.standoff) / self.half_range
            value = (self.snr_max * np.cos(np.minimum(inc, 0.5 * np.pi)) ** self.angle_exponent
                     * (1.0 - self.range_falloff * rel * rel))
            seen = (np.abs(rel) <= 1.0) & (inc <= self.max_incidence_rad) & (value >= self.snr_min)
        return np.where(seen, value, 0.0)

    def sigma(self, snr):
        """Standard deviation of the (non-gross) noise of readings with this SNR."""
        snr = np.asarray(snr, dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(snr > 0, self.sigma_ref * np.sqrt(self.snr_ref / snr), np.nan)

    def gross_error_probability(self, snr):
        snr = np.asarray(snr, dtype=float)
        ramp = (self.gross_snr - snr) / (self.gross_snr - self.snr_min)
        return self.gross_probability * np.clip(ramp, 0.0, 1.0)

    def read(self, true_distance, incidence_rad, rng):
        """Simulate readings: (reading (K,) mm, NaN where there is none; snr (K,), 0 there).

        Draws a fixed number of variates per reading, whether it exists or not, so the noise of
        one spot does not depend on which other spots were seen."""
        d = np.asarray(true_distance, dtype=float)
        k = d.shape[0]
        snr = self.snr(np.where(np.isfinite(d), d, np.inf), incidence_rad)
        scale = np.sqrt(self.snr_ref / np.where(snr > 0, snr, 1.0))
        unit = rng.uniform(-1.0, 1.0, k) if self.noise == "uniform" else None
        if unit is None:
            unit = np.clip(rng.standard_normal(k), -NORMAL_CLIP_SIGMAS, NORMAL_CLIP_SIGMAS)
            unit = unit / NORMAL_CLIP_SIGMAS
        gross_draw = rng.random(k)
        gross_size = rng.uniform(*self.gross_magnitude, k) * rng.choice((-1.0, 1.0), k)
        reading = d + unit * self.accuracy * scale
        gross = gross_draw < self.gross_error_probability(snr)
        reading = np.where(gross, reading + gross_size, reading)
        reading = np.round(reading / self.resolution) * self.resolution
        near, far = self.working_range
        ok = (snr > 0) & (reading >= near) & (reading <= far)
        return np.where(ok, reading, np.nan), np.where(ok, snr, 0.0)

    def to_dict(self):
        out = asdict(self)
        out["gross_magnitude"] = list(self.gross_magnitude)
        return out
