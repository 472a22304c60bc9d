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
