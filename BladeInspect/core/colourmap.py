"""Signed deviation -> colour: blue (material missing) .. green (on nominal) .. red (material
in excess), saturating at +-limit (by default the profile tolerance).

One map feeds everything that shows deviations (report images, FreeCAD's per-point colours,
legends), so a colour means the same deviation everywhere.

The map is built in CIELAB rather than by mixing RGB primaries: its anchors have a lightness
that falls symmetrically from the pale green at zero to equally dark ends, so equal |deviation|
reads as equally strong on both sides and the eye sees no false bands (RGB 'jet' maps put
bright yellow and cyan bands where nothing happens). Hue alone tells the sign.

Points beyond the tolerance are a class of their own, as inspection packages draw them: above
+tolerance magenta, below -tolerance near-black, two colours the ramp never reaches, so the
worst points stand out from the saturated ends of the bar (classed_colours, deviation_classes).
"""

import numpy as np

from .errors import InputError

# (position in [-1, 1], L*, a*, b*): blue, cyan, green, yellow, red. Lightness symmetric about
# zero; chroma kept moderate so every anchor lies inside the sRGB gamut.
_ANCHORS_LAB = np.array([
    [-1.0, 38.0, 21.0, -62.0],
    [-0.5, 66.0, -20.0, -28.0],
    [0.0, 82.0, -55.0, 50.0],
    [0.5, 66.0, 20.0, 65.0],
    [1.0, 38.0, 58.0, 45.0],
])

LUT_SIZE = 511          # odd, so that one entry is exactly zero deviation
NAN_COLOUR = (0.6, 0.6, 0.6)
# Out of tolerance: far in hue or lightness from every colour of the ramp.
ABOVE_COLOUR = (1.0, 0.0, 1.0)
BELOW_COLOUR = (0.08, 0.08, 0.08)
# deviation_classes' values
BELOW, WITHIN, ABOVE = -1, 0, 1

# D65 white point, the reference of sRGB.
_WHITE = np.array([0.95047, 1.0, 1.08883])
_XYZ_TO_LINEAR_RGB = np.array([
    [3.2404542, -1.5371385, -0.4985314],
    [-0.9692660, 1.8760108, 0.0415560],
    [0.0556434, -0.2040259, 1.0572252],
])


def lab_to_srgb(lab):
    """CIELAB (D65) -> sRGB in [0, 1] (clipped), for an (N, 3) array."""
    lab = np.atleast_2d(np.asarray(lab, dtype=float))
    fy = (lab[:, 0] + 16.0) / 116.0
    fx = fy + lab[:, 1] / 500.0
    fz = fy - lab[:, 2] / 200.0
    f = np.column_stack([fx, fy, fz])
    eps = 6.0 / 29.0
    xyz = np.where(f > eps, f ** 3, 3 * eps ** 2 * (f - 4.0 / 29.0)) * _WHITE
    linear = xyz @ _XYZ_TO_LINEAR_RGB.T
    linear = np.clip(linear, 0.0, 1.0)
    return np.where(linear <= 0.0031308, 12.92 * linear,
                    1.055 * np.power(linear, 1.0 / 2.4) - 0.055)


def _build_lut(size=LUT_SIZE):
    pos = np.linspace(-1.0, 1.0, size)
    lab = np.column_stack([np.interp(pos, _ANCHORS_LAB[:, 0], _ANCHORS_LAB[:, k])
                           for k in (1, 2, 3)])
    return lab_to_srgb(lab)


_LUT = _build_lut()


def colourmap_table(size=LUT_SIZE):
    """(size, 3) sRGB colours from -limit to +limit, e.g. for a matplotlib ListedColormap."""
    return _LUT.copy() if size == LUT_SIZE else _build_lut(size)


def _check_limit(limit):
    limit = float(limit)
    if not np.isfinite(limit) or limit <= 0:
        raise InputError("colour limit: must be a positive number of mm, got %r" % (limit,))
    return limit


def deviation_colours(deviation, limit):
    """(N, 3) sRGB floats in [0, 1] for signed deviations (mm); beyond +-limit the end colours,
    NaN grey. Vectorised lookup: a few ms for a quarter of a million points."""
    limit = _check_limit(limit)
    dev = np.asarray(deviation, dtype=float).ravel()
    scaled = np.clip(dev / limit, -1.0, 1.0)
    index = np.rint((np.nan_to_num(scaled) + 1.0) * 0.5 * (LUT_SIZE - 1)).astype(int)
    colours = _LUT[index]
    colours[~np.isfinite(dev)] = NAN_COLOUR
    return colours


def deviation_colours_uint8(deviation, limit):
    """(N, 3) uint8 RGB, for image and mesh formats."""
    return np.rint(deviation_colours(deviation, limit) * 255.0).astype(np.uint8)


def legend_ticks(limit, n_ticks=9):
    """(values (n,), colours (n, 3)): evenly spaced legend values from -limit to +limit (an odd
    count puts one tick at zero) with their colours."""
    limit = _check_limit(limit)
    if int(n_ticks) < 2:
        raise InputError("legend: at least 2 ticks needed, got %r" % (n_ticks,))
    values = np.linspace(-limit, limit, int(n_ticks))
    return values, deviation_colours(values, limit)


def deviation_classes(deviation, tolerance):
    """(N,) int8: ABOVE for deviations beyond +tolerance, BELOW beyond -tolerance, else WITHIN
    (a deviation exactly at the tolerance is within it; NaN is WITHIN, drawn grey)."""
    tolerance = _check_limit(tolerance)
    dev = np.asarray(deviation, dtype=float).ravel()
    classes = np.zeros(dev.shape, dtype=np.int8)
    with np.errstate(invalid="ignore"):
        classes[dev > tolerance] = ABOVE
        classes[dev < -tolerance] = BELOW
    return classes


def classed_colours(deviation, tolerance, limit=None):
    """deviation_colours on the ramp up to +-``limit`` (default the tolerance), with the points
    beyond +-``tolerance`` in ABOVE_COLOUR and BELOW_COLOUR."""
    colours = deviation_colours(deviation, tolerance if limit is None else limit)
    classes = deviation_classes(deviation, tolerance)
    colours[classes == ABOVE] = ABOVE_COLOUR
    colours[classes == BELOW] = BELOW_COLOUR
    return colours


def class_counts(deviation, tolerance):
    """(points below -tolerance, points above +tolerance)."""
    classes = deviation_classes(deviation, tolerance)
    return int(np.count_nonzero(classes == BELOW)), int(np.count_nonzero(classes == ABOVE))
