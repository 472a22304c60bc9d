"""Registered clouds with deviations placed by construction on the demo blade, for the
section-table, verdict, report and batch tests.

Points are taken exactly on the CAD (its own plane cuts), then moved along the CAD's outward
normal by a known field, so every expected figure is computed from that field with numpy,
independently of the code under test.
"""
import numpy as np

from BladeInspect.core.stats import deviation_statistics
from BladeInspect.inspection.result import RegistrationResult
from tests.helpers import demo_nominal  # noqa: F401 (the fixtures' users call fx.demo_nominal)

def surface_points(nominal, levels_z, spacing=0.3, normal=(0.0, 0.0, 1.0)):
    """Points on the CAD's surface along plane cuts at the given heights (mm, along ``normal``
    through the z axis), resampled ``spacing`` mm apart; returns (points (N,3), level index)."""
    from BladeInspect.cad.sections import cut
    normal = np.asarray(normal, dtype=float) / np.linalg.norm(normal)
    pts, which = [], []
    for k, z in enumerate(levels_z):
        for poly in cut(nominal.shape, np.array([0.0, 0.0, z]), normal):
            seg = np.linalg.norm(np.diff(poly, axis=0), axis=1)
            s = np.concatenate([[0.0], np.cumsum(seg)])
            t = np.arange(0.0, s[-1] - 0.5 * spacing, spacing)
            pts.append(np.column_stack([np.interp(t, s, poly[:, i]) for i in range(3)]))
            which.append(np.full(len(t), k))
    return np.vstack(pts), np.concatenate(which)


def profile_points(nominal, levels_z, n_profile=120, edge_skip=2):
    """Points on the CAD near the horizontal sections at the given heights, fast: the demo
    blade's own closed-form profile at each height, projected onto the CAD. The few points
    next to the leading/trailing-edge seams (where the two side faces meet) are left out: a
    point displaced there along one face's normal may be nearest the other face."""
    from BladeInspect.cad.demo_blade import BladeParams, section_points
    params = BladeParams()
    dense = BladeParams(n_profile=n_profile)
    pts, which = [], []
    for k, z in enumerate(levels_z):
        up, lo, _ = section_points(dense, z / params.span)
        keep = slice(edge_skip, n_profile - edge_skip)
        both = np.vstack([up[keep], lo[keep]])
        pts.append(both)
        which.append(np.full(len(both), k))
    return nominal.signed_distance(np.vstack(pts)).closest, np.concatenate(which)


def displaced(nominal, on_surface, deviation):
    """Move surface points by ``deviation`` (mm) along the CAD's outward normal there."""
    base = nominal.signed_distance(on_surface)
    return base.closest + np.asarray(deviation)[:, None] * base.normal


def make_result(nominal, points_cad, columns=None, inlier=None, measured_to_cad=None):
    """A RegistrationResult of points already in the CAD frame, its deviations measured by the
    nominal's exact signed distance as the pipeline does."""
    d = nominal.signed_distance(points_cad)
    n = len(points_cad)
    inlier = np.ones(n, dtype=bool) if inlier is None else np.asarray(inlier, dtype=bool)
    rms = float(np.sqrt(np.mean(d.distance[inlier] ** 2)))
    cov = np.diag([1e-8, 2e-8, 3e-8, 1e-11, 2e-11, 3e-11])
    return RegistrationResult(
        measured_to_cad=np.eye(4) if measured_to_cad is None else measured_to_cad,
        points_cad=np.asarray(points_cad, dtype=float), deviation=d.distance, inlier=inlier,
        closest=d.closest, normal=d.normal, face=d.face, snr=None, columns=columns or {},
        n_rows_skipped=0, rms_mm=rms, pose_covariance=cov, center=points_cad.mean(axis=0),
        pose_uncertainty_mm=0.0005, deviation_stats=deviation_statistics(d.distance),
        coarse={"warning": None}, source="synthetic", cad_source="demo blade")


def bump(points, centre, height, radius):
    """A smooth defect: height * exp(-(r / radius)^2) about ``centre`` (mm)."""
    r2 = np.sum((points - centre) ** 2, axis=1)
    return height * np.exp(-r2 / radius ** 2)
