"""Decision rules: whether a measured value with expanded uncertainty U (k = 2) proves
conformance to its tolerance.

Two rules, named as the standards name them:

- ``iso14253`` (ISO 14253-1, the default): conformance is proven when the value lies in the
  tolerance zone reduced by U at each specified limit, non-conformance when it lies outside the
  zone enlarged by U; in between neither is proven and the verdict is "not proven". It is
  never rounded to pass. When U is at least half the zone's width nothing can be proven to
  conform.
- ``simple`` (simple acceptance, ASME B89.7.3.1 with no guard band): pass inside the tolerance
  zone, fail outside it, U only reported.

A limit may be open (None): a one-sided tolerance. The test uncertainty ratio is the zone's
half width over U (for ±T it is T / U); for a one-sided tolerance it is undefined (None).
"""

from dataclasses import dataclass
from typing import Optional

import numpy as np

PASS, FAIL, NOT_PROVEN = "pass", "fail", "not proven"
RULES = ("iso14253", "simple")
RULE_TEXT = {
    "iso14253": "ISO 14253-1: conformance proven inside the tolerance zone reduced by U, "
                "non-conformance proven outside it enlarged by U, otherwise not proven",
    "simple": "simple acceptance (ASME B89.7.3.1, no guard band): pass inside the tolerance "
              "zone, fail outside it",
}


@dataclass
class Decision:
    verdict: str                 # PASS, FAIL or NOT_PROVEN
    rule: str
    value: float
    expanded_uncertainty: float  # U, k = 2
    lower: Optional[float]
    upper: Optional[float]
    test_uncertainty_ratio: Optional[float]

    def to_json(self):
        return {"verdict": self.verdict, "rule": self.rule, "value": self.value,
                "U": self.expanded_uncertainty, "k": 2, "lower": self.lower,
                "upper": self.upper, "tur": self.test_uncertainty_ratio}


def decide(value, U, lower=None, upper=None, rule="iso14253"):
    """The verdict on ``value`` (with expanded uncertainty ``U`` >= 0) against the tolerance
    zone [lower, upper]; either limit may be None (open)."""
    if rule not in RULES:
        raise ValueError("decision rule must be one of %s, got %r" % (", ".join(RULES), rule))
    if lower is None and upper is None:
        raise ValueError("a tolerance needs at least one limit")
    if lower is not None and upper is not None and lower > upper:
        raise ValueError("tolerance lower limit %g is above the upper %g" % (lower, upper))
    value, U = float(value), float(U)
    if not np.isfinite(value) or not np.isfinite(U) or U < 0:
        raise ValueError("value and U must be finite with U >= 0, got %r, %r" % (value, U))
    guard = U if rule == "iso14253" else 0.0
    below_lo = lower is not None and value < lower - guard
    above_hi = upper is not None and value > upper + guard
    inside_lo = lower is None or value >= lower + guard
    inside_hi = upper is None or value <= upper - guard
    if below_lo or above_hi:
        verdict = FAIL
    elif inside_lo and inside_hi:
        verdict = PASS
    else:
        verdict = NOT_PROVEN
    tur = None
    if lower is not None and upper is not None:
        tur = float("inf") if U == 0 else (upper - lower) / (2.0 * U)
    return Decision(verdict=verdict, rule=rule, value=value, expanded_uncertainty=U,
                    lower=lower, upper=upper, test_uncertainty_ratio=tur)


def combine(verdicts):
    """The part's verdict from its judged values': any fail fails it; otherwise any not proven
    leaves it not proven; pass only when every one passed. None for no judged value."""
    verdicts = list(verdicts)
    if not verdicts:
        return None
    if FAIL in verdicts:
        return FAIL
    if NOT_PROVEN in verdicts:
        return NOT_PROVEN
    return PASS
