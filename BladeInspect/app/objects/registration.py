"""Registration: the pose of a measurement on a nominal, its uncertainty, the statistics and
every point's deviation as a document object; and the pipeline's RegistrationResult read back
from one."""

import json

import numpy as np

import FreeCAD

from ...core.contracts import json_default
from ...inspection import pipeline
from ...inspection.result import RegistrationResult
from .. import registration_fit
from .measurement import pointset_of
from .nominal import nominal_of
from .base import Proxy, add_property, building, finish, shape_signature, signature


def _matrix(T):
    T = np.asarray(T, dtype=float)
    return FreeCAD.Matrix(*T.ravel().tolist())


def matrix_array(m):
    return np.array(m.A, dtype=float).reshape(4, 4)


class Registration(Proxy):
    """Pose of a measurement on a nominal (measured -> CAD), its uncertainty, the statistics and
    the signed deviation of every point. Re-registers when the measurement, the nominal's shape
    or the seed change; without linked inputs it keeps the result it was made from."""
    Type = "BladeInspect::Registration"

    def add_properties(self, obj):
        add = add_property
        g = "Inputs"
        add(obj, "App::PropertyLink", "Measurement", g, "Measured points")
        add(obj, "App::PropertyLink", "Nominal", g, "Nominal CAD (a Part feature)")
        add(obj, "App::PropertyInteger", "Seed", g, "Random seed of the coarse stage")
        registration_fit.add_properties(obj, add)   # the fit
        g = "Pose"
        add(obj, "App::PropertyPlacement", "Pose", g, "Measured -> CAD rigid transform",
            read_only=True)
        add(obj, "App::PropertyMatrix", "MeasuredToCad", g,
            "Measured -> CAD 4x4 matrix (as in result.json)", read_only=True)
        add(obj, "App::PropertyFloat", "PoseUncertaintyMm", g,
            "1 sigma displacement at the worst corner of the CAD's bounding box, mm",
            read_only=True)
        add(obj, "App::PropertyFloatList", "PoseCovariance", g,
            "6x6 covariance, row-major: translation mm, rotation rad, about CovarianceCenter",
            read_only=True)
        add(obj, "App::PropertyVector", "CovarianceCenter", g,
            "Point the covariance's rotation is about, CAD frame, mm", read_only=True)
        add(obj, "App::PropertyVector", "TranslationSigmaMm", g,
            "1 sigma of the translation along x, y, z, mm", read_only=True)
        add(obj, "App::PropertyVector", "RotationSigmaDeg", g,
            "1 sigma of the rotation about x, y, z, degrees", read_only=True)
        g = "Statistics"
        for name, tip in (("RmsMm", "RMS of the inliers' deviations, mm"),
                          ("DeviationMinMm", "Smallest signed deviation, mm"),
                          ("DeviationMaxMm", "Largest signed deviation, mm"),
                          ("DeviationMeanMm", "Mean deviation, mm"),
                          ("DeviationStdMm", "Standard deviation about the mean, mm"),
                          ("PctWithin1Sigma", "% of points within mean +- 1 sigma"),
                          ("PctWithin3Sigma", "% of points within mean +- 3 sigma")):
            add(obj, "App::PropertyFloat", name, g, tip, read_only=True)
        add(obj, "App::PropertyInteger", "NPoints", g, "Registered points", read_only=True)
        add(obj, "App::PropertyInteger", "NInliers", g, "Points the fit used", read_only=True)
        add(obj, "App::PropertyStringList", "Warnings", g, "Warnings of the pipeline",
            read_only=True)
        add(obj, "App::PropertyString", "StatisticsJson", g,
            "deviation statistics with the histogram, as in result.json", hidden=True)
        add(obj, "App::PropertyString", "CoarseJson", g,
            "coarse stage (PCA candidates), as in result.json", hidden=True)
        g = "Deviations"
        add(obj, "App::PropertyFloatList", "PointsCad", g,
            "Registered points in the CAD frame, flattened x, y, z, mm", hidden=True)
        add(obj, "App::PropertyFloatList", "Deviation", g,
            "Signed deviation of every point, + outside material, mm", hidden=True)
        add(obj, "App::PropertyIntegerList", "Inlier", g, "1 where the fit used the point",
            hidden=True)
        add(obj, "App::PropertyString", "InputSignature", g,
            "Signature of the inputs the result was made from", hidden=True)

    def signature(self, obj):
        if obj.Measurement is None or obj.Nominal is None:
            return ""
        m = obj.Measurement
        return signature(np.asarray(m.Coordinates), np.asarray(m.SNR),
                         shape_signature(obj.Nominal.Shape), obj.Seed,
                         *registration_fit.signature_part(obj))

    def execute(self, obj):
        signature = self.signature(obj)
        if not signature or signature == obj.InputSignature:
            return
        nominal = nominal_of(obj.Nominal)
        result = pipeline.register(nominal, pointset_of(obj.Measurement), seed=obj.Seed,
                                   **registration_fit.register_options(obj))
        registration_fit.refit(obj, result, nominal)
        store_registration(obj, result)
        obj.InputSignature = signature


def store_registration(obj, result):
    T = np.asarray(result.measured_to_cad, dtype=float)
    obj.MeasuredToCad = _matrix(T)
    obj.Pose = FreeCAD.Placement(_matrix(T))
    cov = np.asarray(result.pose_covariance, dtype=float)
    obj.PoseCovariance = cov.ravel().tolist()
    sigma = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    obj.TranslationSigmaMm = FreeCAD.Vector(*sigma[:3])
    obj.RotationSigmaDeg = FreeCAD.Vector(*np.degrees(sigma[3:]))
    obj.CovarianceCenter = FreeCAD.Vector(*np.asarray(result.center, dtype=float))
    obj.PoseUncertaintyMm = float(result.pose_uncertainty_mm)
    stats = result.deviation_stats
    obj.RmsMm = float(result.rms_mm)
    obj.DeviationMinMm = float(stats["min"])
    obj.DeviationMaxMm = float(stats["max"])
    obj.DeviationMeanMm = float(stats["mean"])
    obj.DeviationStdMm = float(stats["std"])
    obj.PctWithin1Sigma = float(stats["pct_within_1sigma"])
    obj.PctWithin3Sigma = float(stats["pct_within_3sigma"])
    obj.NPoints = result.n_points
    obj.NInliers = result.n_inliers
    obj.Warnings = [str(w) for w in result.warnings]
    obj.StatisticsJson = json.dumps(stats, default=json_default)
    obj.CoarseJson = json.dumps(result.coarse, default=json_default)
    obj.PointsCad = np.asarray(result.points_cad, dtype=float).ravel().tolist()
    obj.Deviation = np.asarray(result.deviation, dtype=float).tolist()
    obj.Inlier = np.asarray(result.inlier, dtype=int).tolist()
    registration_fit.store(obj, result)


def make_registration(doc, result, measurement=None, nominal=None, seed=0,
                      name="Registration", fit_choice=None):
    """A Registration holding `result` (the pipeline's RegistrationResult). With `measurement`
    and `nominal` linked it re-registers when they change; without, it keeps `result`.
    ``fit_choice``: the inspection.fitting.FitChoice `result` was moved by (default none)."""
    with building(doc, "Registration"):
        obj = doc.addObject("App::FeaturePython", name)
        Registration(obj)
        obj.Measurement = measurement
        obj.Nominal = nominal
        obj.Seed = int(seed)
        if fit_choice is not None:
            registration_fit.set_choice(obj, fit_choice)
        store_registration(obj, result)
        finish(obj)
    return obj


def registration_points(obj):
    """(points in the CAD frame (N, 3), deviation (N,), inlier (N,) bool) of a Registration."""
    return (np.asarray(obj.PointsCad, dtype=float).reshape(-1, 3),
            np.asarray(obj.Deviation, dtype=float),
            np.asarray(obj.Inlier, dtype=bool))


def registration_result(obj, nominal):
    """The pipeline's RegistrationResult of a Registration object, for the stages after it
    (sections, reports). The closest points, normals and faces are not stored in the document;
    they are the nominal's exact signed distance of the stored points."""
    points, deviation, inlier = registration_points(obj)
    dist = nominal.signed_distance(points)
    columns = {}
    if obj.Measurement is not None and len(obj.Measurement.Coordinates) == 3 * len(points):
        columns = pointset_of(obj.Measurement).columns
    snr = None
    if obj.Measurement is not None and len(obj.Measurement.SNR) == len(points):
        snr = np.asarray(obj.Measurement.SNR, dtype=float)
    result = RegistrationResult(
        measured_to_cad=matrix_array(obj.MeasuredToCad), points_cad=points,
        deviation=deviation, inlier=inlier, closest=dist.closest, normal=dist.normal,
        face=dist.face, snr=snr, columns=columns, n_rows_skipped=0, rms_mm=obj.RmsMm,
        pose_covariance=np.asarray(obj.PoseCovariance, dtype=float).reshape(6, 6),
        center=np.array(obj.CovarianceCenter, dtype=float),
        pose_uncertainty_mm=obj.PoseUncertaintyMm,
        deviation_stats=json.loads(obj.StatisticsJson or "{}"),
        coarse=json.loads(obj.CoarseJson or "{}"), warnings=list(obj.Warnings),
        source=obj.Measurement.SourceFile if obj.Measurement is not None else "",
        cad_source=obj.Nominal.Label if obj.Nominal is not None else "")
    registration_fit.restore(obj, result)   # the weights used
    return result
