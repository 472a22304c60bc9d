"""The sections of an inspection: its planned nominal sections, measured from the points the
rig read along the planned paths. The blind scan's points only place the part; its passes are
not sections of the result. `inspect`, and the report, section analysis and airfoil analysis
of an inspection's registration, all take Table 2 from here, so they judge the same sections.
"""

from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

from ..core.errors import InputError
from . import sections as sections_mod


@dataclass(frozen=True)
class PlannedSections:
    """An inspection's sections: ``heights_pct`` the planned nominal heights (% of span),
    ``first_row`` the first row measured along the planned paths, ``n_rows`` how many rows
    from there (None: all the rest)."""
    heights_pct: Tuple[float, ...]
    first_row: int
    n_rows: Optional[int] = None

    def rows(self, n_points):
        """The planned rows of a result of ``n_points`` rows; InputError when they are not
        inside it."""
        first = int(self.first_row)
        end = n_points if self.n_rows is None else first + int(self.n_rows)
        if not 0 <= first < end <= n_points:
            raise InputError("inspection sections: planned rows %d to %d are outside the "
                             "%d points" % (first, end - 1, n_points))
        return np.arange(first, end)

    def table(self, result, nominal, span_axis=None, cmm=None):
        """Table 2 at the planned heights from the planned rows, its point indices into the
        whole result (so the verdict judges the same points as the table)."""
        rows = self.rows(len(result.points_cad))
        table = sections_mod.section_table(result.planned_rows(rows), nominal,
                                           heights_pct=list(self.heights_pct),
                                           span_axis=span_axis, cmm=cmm)
        for sec in table.sections:
            sec.point_index = sec.point_index + rows[0]
        return table
