"""Reconstruction: a measurement's section curves and lofted surfaces as a document object."""

import json

import numpy as np

from ...cad import loft
from ...core.contracts import json_default
from ...core.errors import InputError
from .base import HIDDEN, READ_ONLY, Proxy, add_table, building, finish, signature
from .measurement import pointset_of


class Reconstruction(Proxy):
    """Cubic B-spline section curves and the lofted surfaces through them (paper 3.1.2)."""
    Type = "BladeInspect::Reconstruction"

    def add_properties(self, obj):
        add_table(obj, "Reconstruction", (
            ("App::PropertyLink", "Measurement", "Measurement whose section lines are fitted"),
            ("App::PropertyFloatList", "FitErrors", "RMS fit error of each section curve, mm",
             READ_ONLY),
            ("App::PropertyFloat", "MaxFitErrorMm",
             "Largest distance of a measured point from its section curve, mm", READ_ONLY),
            ("App::PropertyString", "FitErrorsJson",
             "Fit errors per curve (section, side, rms, max) as cad.loft reports them", HIDDEN),
            ("App::PropertyInteger", "NCurves", "Section curves", READ_ONLY),
            ("App::PropertyInteger", "NSurfaces", "Lofted surfaces", READ_ONLY),
            ("App::PropertyString", "InputSignature",
             "Signature of the inputs the shape was made from", HIDDEN)))

    def signature(self, obj):
        return signature(np.asarray(obj.Measurement.Coordinates),
                         [(n, getattr(obj.Measurement, "Column_" + n, None))
                          for n in obj.Measurement.ColumnNames])

    def execute(self, obj):
        if obj.Measurement is None:
            raise InputError("%s: no measurement linked" % obj.Label)
        signature = self.signature(obj)
        if signature == obj.InputSignature and not obj.Shape.isNull():
            return
        store_reconstruction(obj, loft.reconstruct(pointset_of(obj.Measurement)))
        obj.InputSignature = signature


def store_reconstruction(obj, recon):
    import Part
    shapes = [c.toShape() for c in recon.curves] + [s.toShape() for s in recon.surfaces]
    obj.Shape = Part.Compound(shapes)
    errors = list(recon.fit_errors)
    # cad.loft reports a dict per curve (section, side, n_points, rms, max).
    obj.FitErrors = [float(e["rms"]) for e in errors]
    obj.MaxFitErrorMm = max((float(e["max"]) for e in errors), default=0.0)
    obj.FitErrorsJson = json.dumps(errors, default=json_default)
    obj.NCurves = len(recon.curves)
    obj.NSurfaces = len(recon.surfaces)


def make_reconstruction(doc, measurement, reconstruction=None, name="Reconstruction"):
    """A Reconstruction of `measurement`; from `reconstruction` (cad.loft's result) when the
    caller already computed it, else computed here."""
    with building(doc, "Reconstruction"):
        obj = doc.addObject("Part::FeaturePython", name)
        Reconstruction(obj)
        obj.Measurement = measurement
        if reconstruction is None:
            obj.Proxy.execute(obj)
        else:
            store_reconstruction(obj, reconstruction)
        finish(obj)
    return obj
