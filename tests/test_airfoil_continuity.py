"""The edge points and the max-thickness position are continuous functions of the points
(issue 16 item 5: a quantity that jumps when the points move a little has no U a smooth draw
model can state). A noisy double-circular-arc section (closed-form truth, tests/airfoil_shapes)
is moved in tiny steps along a path between two noise realisations (each point moves by at
most a few nanometres a step): every step's change of the LE/TE points and of the
max-thickness position must be bounded and proportionate. The former rules (the largest
circle's zoomed parabola; the extended camber line meeting the smoothing spline) moved the
position by 6.9 um in one of these steps while the neighbouring steps moved it by 0.08 um."""
import unittest

import numpy as np

from BladeInspect.core import airfoil
from tests.airfoil_shapes import ArcSection

SIGMA = 0.002
STEPS = 11
T0, DT = 0.072, 0.001          # the path's angle between the two noise fields (radians)


def _normals(points):
    t = np.roll(points, -1, 0) - np.roll(points, 1, 0)
    t /= np.linalg.norm(t, axis=1)[:, None]
    n = np.column_stack([t[:, 1], -t[:, 0]])
    x, y = points[:, 0], points[:, 1]
    ccw = np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) > 0
    return n if ccw else -n


class SmallMovesSmallChanges(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.sec = ArcSection()
        base = cls.sec.points(0.02)
        normal = _normals(base)
        n1, n2 = np.random.default_rng(7).normal(0.0, SIGMA, (2, len(base)))
        cls.rows, cls.moves = [], []
        prev = None
        for k in range(STEPS):
            t = T0 + k * DT
            pts = base + (np.cos(t) * n1 + np.sin(t) * n2)[:, None] * normal
            if prev is not None:
                cls.moves.append(float(np.max(np.linalg.norm(pts - prev, axis=1))))
            prev = pts
            ch = airfoil.characteristics(pts, noise_mm=SIGMA)
            cls.rows.append(np.concatenate([ch.le_point, ch.te_point, [
                ch.max_thickness_pos_pct / 100.0 * ch.nose_tail_chord_mm]]))
        cls.rows = np.array(cls.rows)

    def test_the_points_move_by_nanometres(self):
        self.assertLess(max(self.moves), 1e-5)

    def test_values_near_the_closed_form(self):
        sec = self.sec
        for row in self.rows:
            self.assertLess(np.linalg.norm(row[:2] - sec.le_point()), 0.005)
            self.assertLess(np.linalg.norm(row[2:4] - sec.te_point()), 0.005)
            self.assertAlmostEqual(row[4], sec.max_thickness_pos_pct() / 100 * sec.chord(),
                                   delta=0.5)

    def test_edge_points_move_proportionately(self):
        step = np.linalg.norm(np.diff(self.rows[:, :4], axis=0).reshape(-1, 2, 2), axis=2)
        # points moving by < 10 nm a step: an edge point moving by more than 20 nm has jumped
        self.assertLess(float(step.max()), 2e-5, step)

    def test_max_thickness_position_moves_proportionately(self):
        step = np.abs(np.diff(self.rows[:, 4]))
        # a flat maximum amplifies a move (0.13 um a step here, the points < 10 nm): within
        # 3x the steps' median, and never a jump to another local maximum
        self.assertLess(float(step.max()), 3.0 * float(np.median(step)) + 1e-4, step)


if __name__ == "__main__":
    unittest.main()
