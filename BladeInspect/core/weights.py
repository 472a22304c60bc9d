"""The readings' weights from the sensor's noise model.

A conoscopic sensor measures a distance along its beam: a reading's error is a displacement
along the beam of standard deviation sigma_beam(SNR) = sigma_ref sqrt(SNR_ref / SNR)
(rig.sensor.SensorModel). What the fit sees is the signed distance to the surface, and an
error of e along a beam at incidence theta (between the beam and the surface normal) moves
the point by e cos(theta) along the normal (the tangential part changes the distance only to
second order in e / curvature radius). So a reading's noise along the normal is

    sigma_n = sigma_beam(SNR) cos(theta),

and the maximum-likelihood (efficient) weights of the point-to-surface fit are 1 / sigma_n^2,
not the paper's SNR-linear 1 / sigma_beam^2: a grazing reading has a low SNR but its error
lies mostly along the surface.

theta is the angle between the beam, carried into the CAD frame by the current pose, and the
CAD's normal at the point's closest point, so the weights follow the pose during ICP
(core.icp's ``weight_model``, through normalised_weights). The beam is known in the measured (rotary-table) frame from each
reading's rotary angle: the machine-frame beam turned back about the rotary axis as the
kinematics turn the readings back (beam_in_table).
"""

import numpy as np

from .errors import InputError
from .transforms import rotation_from_vector

WEIGHT_MODELS = ("snr", "sensor")


def normalised_weights(weight_model, transform, normals, n):
    """a_i of core.icp from a weight model: its weights at pose ``transform`` and these CAD
    normals, 0 where unusable, divided by their mean over the usable points like the SNR
    weights (so sigma0 stays the noise of a typical point)."""
    w = np.asarray(weight_model(transform, normals), dtype=float)
    if w.shape != (n,):
        raise InputError("icp: weight model gave shape %s, expected (%d,)" % (w.shape, n))
    w = np.where(np.isfinite(w) & (w > 0), w, 0.0)
    positive = w > 0
    return w / w[positive].mean() if positive.any() else w


def beam_in_table(angle_deg, axis_direction, beam_machine):
    """(N,3) unit beam directions in the rotary table's frame of readings taken at these
    rotary angles. The table frame is the machine frame turned back by the angle about the
    axis (rig.kinematics.RigKinematics.table_point: t = R(angle)^T (m - a) + a), so a
    direction turns by R(angle)^T; the axis point does not enter."""
    angle = np.asarray(angle_deg, dtype=float).reshape(-1)
    if not np.all(np.isfinite(angle)):
        raise InputError("angle_deg: every reading needs a finite rotary angle for the "
                         "sensor weights")
    axis = np.asarray(axis_direction, dtype=float)
    axis = axis / np.linalg.norm(axis)
    beam = np.asarray(beam_machine, dtype=float)
    beam = beam / np.linalg.norm(beam)
    out = np.empty((len(angle), 3))
    values, index = np.unique(angle, return_inverse=True)
    for k, value in enumerate(values):
        out[index == k] = rotation_from_vector(axis * np.radians(value)).T @ beam
    return out


class SensorWeights:
    """The weight model w_i = 1 / sigma_n,i^2 of the module docstring, for core.icp.

    ``snr`` (N,), ``beam`` (N,3) unit directions in the measured frame; ``sigma_ref`` and
    ``snr_ref`` the sensor's noise at its reference SNR; ``max_incidence_rad`` the largest
    incidence at which the sensor gives a reading at all. cos(theta) is floored at its cosine:
    a point whose beam meets the CAD more obliquely than any reading can was not read there,
    so the excess is the current pose's error, not the reading's (and the floor bounds the
    weight of a reading the pose still puts at grazing)."""

    def __init__(self, snr, beam, sigma_ref, snr_ref, max_incidence_rad):
        self.snr = np.asarray(snr, dtype=float).reshape(-1)
        self.beam = np.asarray(beam, dtype=float).reshape(-1, 3)
        if len(self.beam) != len(self.snr):
            raise InputError("sensor weights: %d beams for %d readings"
                             % (len(self.beam), len(self.snr)))
        if not (np.isfinite(sigma_ref) and sigma_ref > 0 and np.isfinite(snr_ref)
                and snr_ref > 0):
            raise InputError("sensor weights: sigma_ref and snr_ref must be positive")
        if not 0 < max_incidence_rad < 0.5 * np.pi:
            raise InputError("sensor weights: max_incidence_rad must be in (0, pi/2)")
        self.sigma_ref = float(sigma_ref)
        self.snr_ref = float(snr_ref)
        self.max_incidence_rad = float(max_incidence_rad)

    def subset(self, index):
        return SensorWeights(self.snr[index], self.beam[index], self.sigma_ref, self.snr_ref,
                             self.max_incidence_rad)

    def beam_sigma(self):
        """sigma_beam(SNR) of every reading (inf where the SNR is not positive)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.snr > 0, self.sigma_ref * np.sqrt(self.snr_ref / self.snr),
                            np.inf)

    def cos_incidence(self, transform, normals):
        """|cos theta| between each beam carried into the CAD frame by ``transform``
        (measured -> CAD) and the CAD normal, floored at cos(max_incidence_rad); NaN where the
        normal is not finite."""
        beam_cad = self.beam @ np.asarray(transform, dtype=float)[:3, :3].T
        cos = np.abs(np.einsum("ij,ij->i", beam_cad, np.asarray(normals, dtype=float)))
        return np.maximum(cos, np.cos(self.max_incidence_rad))

    def normal_sigma(self, transform, normals):
        return self.beam_sigma() * self.cos_incidence(transform, normals)

    def __call__(self, transform, normals):
        """1 / sigma_n^2 (mm^-2) at this pose, 0 where the reading or the normal is
        unusable."""
        with np.errstate(divide="ignore", invalid="ignore"):
            w = 1.0 / self.normal_sigma(transform, normals) ** 2
        return np.where(np.isfinite(w), w, 0.0)

    def describe(self):
        return {"model": "sensor", "sigma_ref_mm": self.sigma_ref, "snr_ref": self.snr_ref,
                "max_incidence_deg": float(np.degrees(self.max_incidence_rad)),
                "normal_noise": "sigma_ref sqrt(snr_ref / snr) cos(incidence)"}
