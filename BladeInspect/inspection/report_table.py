"""The tables and figures of report.html and report.pdf: the one table layout the report's,
the fit page's and the airfoil pages' tables share (matplotlib), the HTML table and the
embedded PNG figures."""
import base64
import html
import io
import textwrap
from dataclasses import dataclass

# Resolution of the figures embedded in report.html.
DPI = 110


def mpl():
    """(pyplot, ListedColormap, Normalize) on the Agg backend (no display needed)."""
    import matplotlib
    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap, Normalize
    return plt, ListedColormap, Normalize


def html_table(header, rows):
    out = ["<table>"]
    if header:
        out.append("<tr>" + "".join("<th>%s</th>" % html.escape(h) for h in header) + "</tr>")
    for row in rows:
        out.append("<tr>" + "".join("<td>%s</td>" % html.escape(str(c)) for c in row) + "</tr>")
    out.append("</table>")
    return "\n".join(out)


def png_bytes(fig):
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI)
    return buf.getvalue()


def img_tag(png, alt):
    return '<img alt="%s" src="data:image/png;base64,%s">' % (
        html.escape(alt), base64.b64encode(png).decode("ascii"))


@dataclass
class TableStyle:
    """How a PDF table is set: its font size (fixed: matplotlib's automatic size shrinks a
    long table until it cannot be read), its title's size, where it sits in its axes, how its
    cells align and its columns' widths (None: even)."""
    fontsize: float
    title_size: float = 11
    loc: str = "upper left"
    cell_loc: str = "right"
    col_widths: list = None


def pdf_table(fig, rect, header, rows, style, title=None):
    """The table of ``rows`` under ``header`` in a frameless axes at ``rect`` (figure
    fractions), set in ``style`` (a TableStyle), titled at its left when ``title`` is given.
    Returns the axes."""
    ax = fig.add_axes(rect)
    ax.axis("off")
    if title:
        ax.set_title(title, fontsize=style.title_size, loc="left")
    table = ax.table(cellText=rows, colLabels=header, loc=style.loc, cellLoc=style.cell_loc,
                     colWidths=style.col_widths)
    table.auto_set_font_size(False)
    table.set_fontsize(style.fontsize)
    shrink_to_cells(fig, table)
    return ax


# The smallest a cell's text is set on one line to fit its cell (pt); a text that needs less
# is broken over lines that share the row's height (ROW_HEIGHT_PT).
MIN_CELL_FONT_PT = 5.0


def shrink_to_cells(fig, table):
    """Fit the text of each cell that is wider than its cell (a long row label in a narrow
    column): set smaller until it fits, down to MIN_CELL_FONT_PT, then broken over as many
    lines as it needs in a font that puts them all in the row's height. Every other cell keeps
    the table's size."""
    renderer = fig.canvas.get_renderer()
    for cell in table.get_celld().values():
        text = cell.get_text()
        if not text.get_text():
            continue
        room = cell.get_window_extent(renderer).width * (1.0 - 2.0 * cell.PAD)
        need = text.get_window_extent(renderer).width
        if need <= room or room <= 0:
            continue
        size = text.get_fontsize() * room / need * 0.97
        if size >= MIN_CELL_FONT_PT:
            text.set_fontsize(size)
            continue
        words = text.get_text()
        for n_lines in range(2, 6):
            size = min(MIN_CELL_FONT_PT, ROW_HEIGHT_PT / (1.25 * n_lines))
            text.set_fontsize(size)
            text.set_text("\n".join(textwrap.wrap(words, max(1, int(len(words) / n_lines) + 1),
                                                   break_long_words=True)))
            if text.get_window_extent(renderer).width <= room:
                break


# matplotlib sizes a table's rows for its default 10 pt text (1.2 x 10 pt) whatever font size is
# set afterwards, and lets a table longer than its axes run off the page: how many rows a
# rectangle holds follows from this height, not from the font.
ROW_HEIGHT_PT = 12.0
PORTRAIT = (8.27, 11.69)
FULL_PAGE = [0.06, 0.05, 0.88, 0.88]


def rows_that_fit(fig, rect):
    """How many rows under the header a table at ``rect`` (figure fractions) of ``fig`` shows."""
    return max(1, int(rect[3] * fig.get_figheight() * 72.0 / ROW_HEIGHT_PT) - 1)


def pdf_table_pages(plt, header, rows, style, title, first=None, figsize=PORTRAIT,
                    rect=FULL_PAGE):
    """The table of ``rows`` over as many pages as it needs, none cut off, set in ``style`` (a
    TableStyle). ``first``: (fig, rect) of a page begun elsewhere that takes the first rows, or
    None. Pages after the first repeat the header under '<title> (continued)'. Returns the
    figures this made (not ``first``'s), for the caller to save and close."""
    rows = list(rows)
    made = []
    fig, at = first if first is not None else (None, None)
    page_title = title
    while True:
        if fig is None:
            fig, at = plt.figure(figsize=figsize), rect
            made.append(fig)
        n = rows_that_fit(fig, at)
        pdf_table(fig, at, header, rows[:n] or [["-"] * len(header)], style, title=page_title)
        rows = rows[n:]
        if not rows:
            return made
        fig, page_title = None, "%s (continued)" % title
