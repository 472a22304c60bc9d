"""A CSV of plain numbers is parsed by numpy in one pass (core.pointio._all_numbers, issue 14
speed); every value must be the double Python's float() gives for its field, which is the
truth here, whatever the field's spelling - and a field numpy reads differently or not at all
must leave the file to the field-by-field parser."""
import os
import shutil
import tempfile
import unittest

import numpy as np

from BladeInspect.core import pointio


def spell(rng, value):
    """One of the ways a writer may put a number in a field."""
    forms = ["%.6f", "%.17g", "%g", "%.3e", "%+.4f", " %.6f ", "%.6E", "%.0f."]
    return rng.choice(forms) % value


class NumericCsv(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="bi-numbers-")

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def read(self, header, rows, line_end="\n"):
        path = os.path.join(self.dir, "p.csv")
        with open(path, "w", newline="") as fh:
            fh.write(header + line_end + line_end.join(",".join(r) for r in rows) + line_end)
        return pointio.read_points(path)

    def test_values_are_float_of_each_field(self):
        rng = np.random.default_rng(14)
        for trial in range(20):
            n = int(rng.integers(10, 400))
            values = rng.normal(0.0, 10.0 ** rng.uniform(-3, 3), (n, 5))
            values[:, 3] = rng.uniform(0.0, 100.0, n)
            rows = [[spell(rng, v) for v in row] for row in values]
            if trial % 3 == 0:   # a sensor's "no reading": the row is skipped
                rows[int(rng.integers(n))][int(rng.integers(3))] = "nan"
            line_end = "\r\n" if trial % 2 else "\n"
            ps = self.read("x,y,z,snr,angle_deg", rows, line_end)
            truth = np.array([[float(f) for f in row] for row in rows])
            usable = np.all(np.isfinite(truth[:, :4]), axis=1)
            np.testing.assert_array_equal(ps.xyz, truth[usable, :3])
            np.testing.assert_array_equal(ps.snr, truth[usable, 3])
            np.testing.assert_array_equal(ps.columns["angle_deg"], truth[usable, 4])
            self.assertEqual(ps.n_rows_skipped, int((~usable).sum()))

    def test_fields_numpy_reads_otherwise_go_field_by_field(self):
        # float() takes digit underscores, which numpy does not ...
        ps = self.read("x,y,z,snr", [["%d" % i, "1_0", "2.5", "50"] for i in range(12)])
        np.testing.assert_array_equal(ps.xyz[:, 1], np.full(12, 10.0))
        # ... and numpy takes "nan(1)", which is no number to float(): a text column.
        ps = self.read("x,y,z,snr,phase", [["%d" % i, "1", "2.5", "50", "nan(1)"]
                                           for i in range(12)])
        self.assertEqual(list(ps.columns["phase"]), ["nan(1)"] * 12)

if __name__ == "__main__":
    unittest.main()
