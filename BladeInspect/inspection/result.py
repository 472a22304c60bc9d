"""The registration result: everything result.json and deviations.csv are made of, as plain data
that reports, batches, document objects and tests read without recomputing anything."""

import dataclasses
from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from ..core import stats


@dataclass
class RegistrationResult:
    measured_to_cad: np.ndarray            # (4, 4) maps input points into the CAD frame
    points_cad: np.ndarray                 # (N, 3) usable input points, input order, CAD frame
    deviation: np.ndarray                  # (N,) signed distance to the CAD, + outside material
    inlier: np.ndarray                     # (N,) bool: used by the fit (robust weight > 0)
    closest: np.ndarray                    # (N, 3) closest CAD points
    normal: np.ndarray                     # (N, 3) outward unit normals there
    face: np.ndarray                       # (N,) index of the closest face in nominal.faces
    snr: Optional[np.ndarray]              # (N,) or None when the input had none
    columns: dict                          # extra input columns carried through (section, ...)
    n_rows_skipped: int
    rms_mm: float                          # RMS of the inliers' deviations
    pose_covariance: np.ndarray            # (6, 6) translation mm, rotation rad, about `center`
    center: np.ndarray                     # (3,) point the covariance's rotation is about
    pose_uncertainty_mm: float             # 1 sigma at the worst corner of the CAD's bounding box
    deviation_stats: dict                  # core.stats.deviation_statistics of all deviations
    coarse: dict                           # measured_to_cad, eigenvalues, candidates, warning
    timing_s: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    source: str = ""
    cad_source: str = ""
    cad_faces: list = field(default_factory=list)   # how each CAD face's outside was decided
    pose_unmeasured: list = field(default_factory=list)   # inspection.checks.describe_unmeasured
    surface_fit: Optional[dict] = None                     # inspection.checks.surface_fit
    # The Cramer-Rao bound of the fine pose alone (pose_uncertainty_mm when the coarse stage
    # was decided), and whether pose_uncertainty_mm was raised to cover an undecided rival
    # pose (pipeline.uncertainty_with_rival).
    pose_uncertainty_statistical_mm: Optional[float] = None
    pose_uncertainty_includes_rival: bool = False
    # The fine ICP's weights (SNR x robust) per point, the fit objective's record and the
    # fit-sensitivity table (inspection.fitting), written into result.json when present.
    icp_weights: Optional[np.ndarray] = None
    fit: Optional[dict] = None
    fit_sensitivity: Optional[dict] = None
    weights: Optional[dict] = None   # the fine ICP's weight model (inspection.weighting)
    # Where the fine ICP's robust weights reach 0 (core.icp.InlierCut), for the censored
    # model of the part's worst inlier (inspection.uncertainty); not written to files.
    inlier_cut: Optional[object] = None
    # The planner's notes (points or sections it left out, edges it could not plan densely),
    # also among ``warnings``; the report lists them apart as its "Planning notes".
    planning_notes: list = field(default_factory=list)

    def planned_rows(self, rows):
        """The result restricted to some rows (an inspection's points measured after its blind
        scan), for Table 2 at the nominal sections: the section column, which numbers the scan's
        passes rather than those planes, is left out."""
        rows = np.asarray(rows)
        columns = {k: np.asarray(v)[rows] for k, v in self.columns.items() if k != "section"}
        return dataclasses.replace(
            self, points_cad=self.points_cad[rows], deviation=self.deviation[rows],
            inlier=self.inlier[rows], closest=self.closest[rows], normal=self.normal[rows],
            face=self.face[rows], snr=None if self.snr is None else self.snr[rows],
            icp_weights=None if self.icp_weights is None else self.icp_weights[rows],
            inlier_cut=None if self.inlier_cut is None else self.inlier_cut.rows(rows),
            columns=columns, deviation_stats=stats.deviation_statistics(self.deviation[rows]))

    @property
    def n_points(self):
        return int(len(self.deviation))

    @property
    def n_inliers(self):
        return int(np.count_nonzero(self.inlier))


def rival_lines(coarse):
    """Plain-text lines on the coarse stage's rival pose, for the terminal, the report and the
    GUI; empty when there is none or the coarse stage told it apart from the chosen pose."""
    rival = (coarse or {}).get("rival")
    if not rival or rival.get("decided", True):
        return []
    ranking = coarse.get("ranking", {})
    distance = rival.get("distance_from_final_mm", rival["distance_mm"])
    T = np.asarray(rival["measured_to_cad"])
    return ["rival pose (coarse candidate %d) %.4g mm from the result at the worst corner of "
            "the CAD's bounding box; objective %.1f against the chosen pose's %.1f, Vuong "
            "z = %.2f (decided from z >= %.1f); the pose uncertainty covers it"
            % (rival["candidate"], distance, rival["objective"],
               rival["objective"] - rival["objective_difference"], rival["z"],
               ranking.get("decided_z", float("nan")))] + \
        ["rival measured_to_cad row %d: %s" % (k + 1, "  ".join("%.6f" % v for v in T[k]))
         for k in range(3)]

