"""A long table in report.pdf is continued on further pages, never cut off: every row appears
once, and every cell matplotlib draws lies on its page (its own rendered extents, the
independent truth)."""
import unittest

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt   # noqa: E402

from BladeInspect.inspection import report_table   # noqa: E402


def drawn_cells(fig):
    """(text, extent in figure fractions) of every table cell on ``fig``."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    out = []
    for ax in fig.axes:
        for table in ax.tables:
            for cell in table.get_celld().values():
                box = cell.get_window_extent(renderer).transformed(fig.transFigure.inverted())
                out.append((cell.get_text().get_text(), box))
    return out


class TablePages(unittest.TestCase):
    def check(self, n_rows, first_rect=None):
        header = ["characteristic", "value"]
        rows = [["row %d" % i, "%.3f" % i] for i in range(n_rows)]
        figs = []
        first = None
        if first_rect is not None:
            figs.append(plt.figure(figsize=report_table.PORTRAIT))
            first = (figs[0], first_rect)
        figs += report_table.pdf_table_pages(plt, header, rows, report_table.TableStyle(6.5),
                                             "Long table", first=first)
        try:
            seen = []
            for fig in figs:
                for text, box in drawn_cells(fig):
                    self.assertGreaterEqual(box.y0, -1e-9, text)
                    self.assertLessEqual(box.y1, 1 + 1e-9, text)
                    if text.startswith("row "):
                        seen.append(text)
            self.assertEqual(sorted(seen), sorted(r[0] for r in rows))
            return len(figs)
        finally:
            for fig in figs:
                plt.close(fig)

    def test_long_tables_continue_on_pages_of_their_own(self):
        for n in (1, 59, 60, 61, 130, 400):
            pages = self.check(n)
            self.assertLessEqual(pages, 1 + n // 40, n)

    def test_a_page_begun_elsewhere_takes_the_first_rows(self):
        self.assertEqual(self.check(10, [0.06, 0.05, 0.88, 0.4]), 1)
        self.assertGreater(self.check(130, [0.06, 0.05, 0.88, 0.4]), 1)


if __name__ == "__main__":
    unittest.main()
