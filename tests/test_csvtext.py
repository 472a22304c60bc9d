"""core.csvtext against Python's own %-formatting (the way deviations.csv was written before:
one np.char.mod string per value, joined row by row), byte for byte."""
import unittest

import numpy as np

from BladeInspect.core import csvtext


def python_rows(cols, fmts):
    """The previous deviations.csv body: np.char.mod per column, rows joined in Python."""
    text_cols = [np.char.mod(f, c) if f != "%s" else c for f, c in zip(fmts, cols)]
    rows = text_cols[0].astype(object)
    for c in text_cols[1:]:
        rows = rows + "," + c.astype(object)
    return ("\n".join(rows.tolist()) + "\n").encode("utf-8")


def awkward_values(rng, n):
    """Uniform and log-spread values of both signs, exact decimal halves (x.xxxxxx5, whose
    binary value lies just above or below the half), -0.0, tiny negatives that print as
    -0.000000, integers, values too large for the integer path, NaN and infinities."""
    mags = 10.0 ** rng.uniform(-12, 12, n)
    v = np.where(rng.random(n) < 0.5, -1.0, 1.0) * mags
    v[: n // 4] = rng.uniform(-500, 500, n // 4)
    k = n // 8
    halves = (rng.integers(-10 ** 9, 10 ** 9, k) + 0.5) / 1e6
    halves3 = (rng.integers(-10 ** 6, 10 ** 6, k) + 0.5) / 1e3
    v[n // 4: n // 4 + k] = halves
    v[n // 4 + k: n // 4 + 2 * k] = halves3
    special = [0.0, -0.0, -1e-9, 1e-9, -4.9e-7, -5e-7, 5e-7, 0.5, -0.5, 1.5, 2.5, 1e6, -1e6,
               4.5e9, 4.6e9, -7e15, 1e20, -3e300, np.nan, np.inf, -np.inf, 9.9999995, -9.9999995,
               999.9995, 0.0005, 0.0015, -0.0025]
    v[-len(special):] = special
    return v


class FixedPoint(unittest.TestCase):
    def test_columns_match_python_formatting(self):
        for seed in range(4):
            rng = np.random.default_rng(seed)
            n = 5000
            cols = [awkward_values(rng, n) for _ in range(4)]
            snr = awkward_values(rng, n)
            inlier = rng.random(n) < 0.9
            got = csvtext.csv_rows([csvtext.fixed_matrix(c, 6) for c in cols]
                                   + [csvtext.fixed_matrix(snr, 3),
                                      csvtext.integer_matrix(inlier)])
            want = python_rows(cols + [snr, inlier.astype(float)],
                               ["%.6f"] * 4 + ["%.3f", "%d"])
            self.assertEqual(got, want, "seed %d" % seed)

    def test_every_value_alone(self):
        rng = np.random.default_rng(7)
        values = awkward_values(rng, 4000)
        for decimals in (0, 1, 3, 6, 9):
            lines = csvtext.csv_rows([csvtext.fixed_matrix(values, decimals)]).decode().split("\n")
            expected = ["%.*f" % (decimals, v) for v in values]
            self.assertEqual(lines[:-1], expected)
            self.assertEqual(lines[-1], "")

    def test_all_nan_column_and_extra_columns(self):
        """snr absent (all NaN) and a scan's extra columns: %.6g floats and strings."""
        rng = np.random.default_rng(8)
        n = 3000
        x = rng.normal(0, 30, n)
        snr = np.full(n, np.nan)
        angle = awkward_values(rng, n)
        section = rng.integers(-3, 40, n)
        got = csvtext.csv_rows([csvtext.fixed_matrix(x, 6), csvtext.fixed_matrix(snr, 3),
                                csvtext.string_matrix(np.char.mod("%.6g", angle)),
                                csvtext.string_matrix(section.astype(str))])
        want = python_rows([x, snr, angle, section.astype(str)], ["%.6f", "%.3f", "%.6g", "%s"])
        self.assertEqual(got, want)

    def test_integers_truncate_like_percent_d(self):
        values = np.array([0.0, -0.0, 1.0, -1.0, 2.7, -2.7, 123456789.0, -9e15])
        got = csvtext.csv_rows([csvtext.integer_matrix(values)]).decode().split("\n")[:-1]
        self.assertEqual(got, ["%d" % v for v in values])


if __name__ == "__main__":
    unittest.main()
