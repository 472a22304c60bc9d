"""The tables and figures of report.html and report.pdf: the one table layout the report's,
the fit page's and the airfoil pages' tables share (matplotlib), the HTML table and the
embedded PNG figures."""
import base64
import html
import io
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
    return ax


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
