"""A table on a page of report.pdf (matplotlib): the one layout the report's, the fit page's
and the airfoil pages' tables share."""


def pdf_table(fig, rect, header, rows, fontsize, title=None, title_size=11, loc="upper left",
              cell_loc="right", col_widths=None):
    """The table of ``rows`` under ``header`` in a frameless axes at ``rect`` (figure
    fractions), titled at its left when ``title`` is given. The font size is fixed: matplotlib's
    automatic size shrinks a long table until it cannot be read. Returns the axes."""
    ax = fig.add_axes(rect)
    ax.axis("off")
    if title:
        ax.set_title(title, fontsize=title_size, loc="left")
    table = ax.table(cellText=rows, colLabels=header, loc=loc, cellLoc=cell_loc,
                     colWidths=col_widths)
    table.auto_set_font_size(False)
    table.set_fontsize(fontsize)
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


def pdf_table_pages(plt, header, rows, fontsize, title, first=None, figsize=PORTRAIT,
                    rect=FULL_PAGE, **table_options):
    """The table of ``rows`` over as many pages as it needs, none cut off. ``first``: (fig,
    rect) of a page begun elsewhere that takes the first rows, or None. Pages after the first
    repeat the header under '<title> (continued)'. Returns the figures this made (not
    ``first``'s), for the caller to save and close."""
    rows = list(rows)
    made = []
    fig, at = first if first is not None else (None, None)
    page_title = title
    while True:
        if fig is None:
            fig, at = plt.figure(figsize=figsize), rect
            made.append(fig)
        n = rows_that_fit(fig, at)
        pdf_table(fig, at, header, rows[:n] or [["-"] * len(header)], fontsize,
                  title=page_title, **table_options)
        rows = rows[n:]
        if not rows:
            return made
        fig, page_title = None, "%s (continued)" % title
