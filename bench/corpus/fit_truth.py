"""Where the best fit puts a twisted part: the true in-plane rotation of each section after the
rigid least-squares fit, computed from the part's construction (never BladeInspect's ICP).

A twist error is not a fit-free quantity: the rigid fit of the whole blade turns it by some
weighted mean of the twist, and every angle, twist and axial chord a section reports is read
in that fitted frame. The fit's motion is found here as the linear least-squares problem the
fit solves near its optimum, with exact correspondences: a point p of the made part at height
z lies at the nominal point turned back by the twist t(z) about the stacking line, so its
signed distance from the nominal surface is b = n . (t(z) z_hat x (p - c(z))), with n the
made surface's normal from the construction's own closed form (x(s, z) = R(theta(z)) P(s) +
c(z): n = dx/ds x dx/dz). The small motion (omega, delta) that the fit applies minimises
sum w (b + omega . (p x n) + delta . n)^2, with the scan's own SNR weights and point pattern.
A section at nominal height z0 then holds the made section from height z0 - delta_z turned by
omega_z: its rotation relative to the nominal is t(z0) + omega_z - theta'(z0) delta_z.
The tilts (omega_x, omega_y) change a section's angles only to second order; they are
returned so a caller can show they are small."""
import numpy as np
from scipy.spatial import cKDTree

CAP_TOL_MM = 0.01       # a point this close to an end plane is an end-cap point
SIDE_TOL_MM = 0.05      # a side point farther than this from the construction is left out


def _rot2(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s], [s, c]])


def fitted_rotation(case, loop, twist_tip_deg, points, weights):
    """(rel(q) in degrees, info) for a case whose made part is ``loop`` (its station profile in
    the profile's own frame) turned by the case's nominal twist plus ``twist_tip_deg * q`` and
    shifted by its lean, given scan ``points`` on the made part in the CAD frame and their fit
    ``weights``. ``rel(q)``: the section's rotation relative to the nominal after the fit,
    counter-clockwise about +z."""
    loop = np.asarray(loop, float)
    span = float(case.span)
    nominal_twist = case.twist_deg or (lambda q: 0.0)
    lean = case.lean_mm or (lambda q: (0.0, 0.0))
    h = 1e-4

    def theta(q):       # the made part's rotation at span fraction q, radians
        return np.radians(nominal_twist(q) + twist_tip_deg * q)

    def theta_nominal(q):
        return np.radians(nominal_twist(q))

    def shift(q):
        return np.asarray(lean(q), float)

    tree = cKDTree(loop)
    tangent = np.roll(loop, -1, axis=0) - np.roll(loop, 1, axis=0)
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    p = np.asarray(points, float)
    w = np.asarray(weights, float)
    z = p[:, 2]
    rows, rhs, wts = [], [], []
    cap = (np.abs(z) < CAP_TOL_MM) | (np.abs(z - span) < CAP_TOL_MM)
    n_side = n_cap = n_off = 0
    for i in range(len(p)):
        q = z[i] / span
        if cap[i]:
            n = np.array([0.0, 0.0, -1.0 if z[i] < span / 2 else 1.0])
            b = 0.0                          # the twist moves cap points within their plane
            n_cap += 1
        else:
            th, c = theta(q), shift(q)
            local = _rot2(-th) @ (p[i, :2] - c)
            d, j = tree.query(local)
            if d > SIDE_TOL_MM or not (0.0 <= q <= 1.0):
                n_off += 1
                continue
            # the fit measures distances to the nominal: its normal there (the twist turns it
            # by t(z) only, a second-order change of the result)
            R = _rot2(theta_nominal(q))
            ds = np.append(R @ tangent[j], 0.0)
            dth = (theta_nominal(min(q + h, 1.0)) - theta_nominal(max(q - h, 0.0))) / \
                ((min(q + h, 1.0) - max(q - h, 0.0)) * span)
            dc = (shift(min(q + h, 1.0)) - shift(max(q - h, 0.0))) / \
                ((min(q + h, 1.0) - max(q - h, 0.0)) * span)
            rp = R @ loop[j]
            dz = np.array([-rp[1] * dth + dc[0], rp[0] * dth + dc[1], 1.0])
            n = np.cross(ds, dz)
            n /= np.linalg.norm(n)
            outward = np.append(R @ np.array([tangent[j][1], -tangent[j][0]]), 0.0)
            if n @ outward < 0:
                n = -n
            t = np.radians(twist_tip_deg * q)
            e = t * np.cross([0.0, 0.0, 1.0], np.append(p[i, :2] - c, 0.0))
            b = float(n @ e)
            n_side += 1
        rows.append(np.concatenate([np.cross(p[i], n), n]))
        rhs.append(b)
        wts.append(w[i])
    A = np.asarray(rows)
    b = np.asarray(rhs)
    sw = np.sqrt(np.asarray(wts))
    x, *_ = np.linalg.lstsq(A * sw[:, None], -b * sw, rcond=None)
    omega, delta = x[:3], x[3:]

    def rel(q):
        dnom = (np.radians(nominal_twist(min(q + h, 1.0)) - nominal_twist(max(q - h, 0.0)))
                / ((min(q + h, 1.0) - max(q - h, 0.0)) * span))
        r = np.radians(twist_tip_deg * q) + omega[2] - dnom * delta[2]
        return float(np.degrees(r))

    info = {"omega_deg": np.degrees(omega).tolist(), "delta_mm": delta.tolist(),
            "points_side": n_side, "points_cap": n_cap, "points_left_out": n_off}
    return rel, info
