"""The frame the robust fit chose, as a systematic term of a section's angles' U.

The robust ICP gives no weight to readings far from the CAD, so a dent does not tilt the part;
a form error over a wide region (a twist, a size error) is left out the same way, and the part
is then aligned to the rest alone. How far the least-squares frame of every counted point
stands from it is one Gauss-Newton step away (core.frame_shift); its turn about the span, and
its move along the span times the blade's twist rate, turn every section's angles."""
import numpy as np

from ..core.frame_shift import least_squares_shift
from . import airfoil_uncertainty
from .airfoil_verdicts import COVERAGE_FACTOR

# Beyond these, the frame the robust fit chose is noted on every section (fit_frame_note):
# the least-squares frame of every counted point turned about the span, or any point moved.
FRAME_TURN_DEG = 0.002
FRAME_MOVE_MM = 0.002
FRAME_ANGLES = ("stagger_deg", "twist_deg", "inlet_angle_deg", "outlet_angle_deg")


def fit_frame(result, counted, span_axis):
    """The frame shift when the points the robust fit left out as regions that deviate
    (``counted`` and not inliers: measured_surface's grouped rejections) would move the frame:
    aligned to all the counted points (core.frame_shift), the part turns about the span by
    more than FRAME_TURN_DEG or moves a point by more than FRAME_MOVE_MM. A dict (turn deg,
    move mm, dw, dt, c, left-out count and share) or None. On a stator twisted 0.3 deg at the
    tip the fit left out 10 % of the points and stood 0.015 deg from the least-squares frame,
    15 times the stagger's U."""
    if result is None or counted is None or not len(counted):
        return None
    inlier = np.asarray(result.inlier, dtype=bool)
    left_out = counted & ~inlier
    if not left_out.any():
        return None
    weights = np.ones(len(inlier)) if result.snr is None else \
        np.asarray(result.snr, dtype=float) / np.nanmean(result.snr)
    dw, dt, c = least_squares_shift(result.points_cad, result.normal, result.deviation,
                                    weights, counted, inlier)
    axis = np.asarray(span_axis, dtype=float)
    turn = float(np.degrees(dw @ (axis / np.linalg.norm(axis))))
    moved = dt + np.cross(dw, result.points_cad[counted] - c)
    move = float(np.sqrt((moved ** 2).sum(axis=1)).max())
    if abs(turn) <= FRAME_TURN_DEG and move <= FRAME_MOVE_MM:
        return None
    return {"turn_deg": turn, "move_mm": move, "dw": dw, "dt": dt, "c": c,
            "left_out": int(left_out.sum()), "share": float(left_out.mean())}


def twist_rates(results, span_axis):
    """Each section's nominal stagger change per mm along the span (deg/mm), from its
    neighbours' nominal staggers; 0 where fewer than two sections have one. A twisted blade
    moved along its span reads every section turned by that rate times the move."""
    axis = np.asarray(span_axis, dtype=float) / np.linalg.norm(span_axis)
    known = [(i, float(np.asarray(r.plane.origin, dtype=float) @ axis),
              r.block["nominal"]["stagger_deg"]) for i, r in enumerate(results)
             if r.plane is not None and r.block and r.block.get("nominal")
             and r.block["nominal"].get("stagger_deg") is not None]
    rates = [0.0] * len(results)
    if len(known) < 2:
        return rates
    known.sort(key=lambda k: k[1])
    z = np.array([k[1] for k in known])
    stagger = np.degrees(np.unwrap(np.radians([k[2] for k in known])))
    if np.ptp(z) <= 0:
        return rates
    for (i, _, _), rate in zip(known, np.gradient(stagger, z)):
        rates[i] = float(rate)
    return rates


def add_fit_frame(sr, frame, twist_rate, span_axis):
    """The frame's turn about the span, plus the nominal twist rate times the frame's move
    along the span at this section, as a systematic term of the section's angles' U (added
    linearly, as the size take-up: uncertainty_fit_frame), and a note naming what else the
    frame moves."""
    axis = np.asarray(span_axis, dtype=float) / np.linalg.norm(span_axis)
    origin = np.asarray(sr.plane.origin, dtype=float)
    along = float((frame["dt"] + np.cross(frame["dw"], origin - frame["c"])) @ axis)
    angle = abs(frame["turn_deg"]) + abs(twist_rate * along)
    block = sr.block
    text = ("measured: the fit left out %d points (%.1f %%) in regions that deviate; aligned "
            "to every point measured, the part would turn %+.4f\u00b0 about the span, this "
            "section %+.4f mm along it, and its points move up to %.4f mm. "
            % (frame["left_out"], 100.0 * frame["share"], frame["turn_deg"], along,
               frame["move_mm"]))
    if block.get("uncertainty") is not None:
        term = {key: angle for key in FRAME_ANGLES}
        block["uncertainty"], block["uncertainty_fit_frame"], _ = \
            airfoil_uncertainty.add_take_up(block["uncertainty"], term, COVERAGE_FACTOR)
        text += ("U of the stagger, twist and the inlet and outlet angles holds the %.4f\u00b0 "
                 "that makes here; the axial chord and the section's position are read in the "
                 "fitted frame and may be off by up to that move beyond U" % angle)
    else:
        text += ("Stagger, twist, the inlet and outlet angles, the axial chord and the "
                 "section's position are read in the fitted frame and may be off by that much")
    sr.notes.append(text)
