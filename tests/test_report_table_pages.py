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



class CellsHoldTheirText(unittest.TestCase):
    """A row label longer than its column is set smaller until it lies inside its cell (the
    rendered extents of text and cell, the independent truth); short cells keep the size."""

    def test_a_long_label_fits_its_cell(self):
        fig = plt.figure(figsize=report_table.PORTRAIT)
        try:
            rows = [["Pose uncertainty (1 sigma, worst corner, after the planned scan)", "1.2"],
                    ["Translation 1 sigma (x, y, z) after the blind scan", "0.5"],
                    ["RMS", "0.002"]]
            report_table.pdf_table(fig, [0.06, 0.5, 0.5, 0.2], ["Quantity", "Value"], rows,
                                   report_table.TableStyle(7.5, cell_loc="left",
                                                           col_widths=[0.45, 0.55]))
            fig.canvas.draw()
            renderer = fig.canvas.get_renderer()
            table = fig.axes[0].tables[0]
            for (row, col), cell in table.get_celld().items():
                text = cell.get_text()
                inside, box = text.get_window_extent(renderer), cell.get_window_extent(renderer)
                self.assertLessEqual(inside.width, box.width, text.get_text())
                self.assertLessEqual(inside.height, box.height, text.get_text())
                if text.get_text() in ("RMS", "0.002", "1.2", "Quantity", "Value"):
                    self.assertEqual(text.get_fontsize(), 7.5)
        finally:
            plt.close(fig)

if __name__ == "__main__":
    unittest.main()
