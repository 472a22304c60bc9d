"""Measurement: measured points with their SNR and extra columns as a document object."""

import os

import numpy as np

from ...core.errors import InputError
from ...core.pointio import PointSet
from ...inspection import pipeline
from .base import (HIDDEN, READ_ONLY, Proxy, add_property, add_table, attach_view, building,
                   file_signature, points_kernel)


class Measurement(Proxy):
    """Measured points with their SNR and extra columns (section, angle_deg, ...). Coordinates
    are kept in double precision in `Coordinates`; the `Points` kernel (single precision) is
    for display only."""
    Type = "BladeInspect::Measurement"

    def add_properties(self, obj):
        add_table(obj, "Measurement", (
            ("App::PropertyFile", "SourceFile",
             "Point file read into this measurement (empty: made in memory)"),
            ("App::PropertyFloatList", "Coordinates",
             "x, y, z of every point, flattened, mm (double precision)", HIDDEN),
            ("App::PropertyFloatList", "SNR",
             "Signal-to-noise ratio of every point, 0..100 (empty: none measured)", HIDDEN),
            ("App::PropertyStringList", "ColumnNames",
             "Extra columns carried through (each stored as Column_<name>)", READ_ONLY),
            ("App::PropertyInteger", "NPoints", "Usable points", READ_ONLY),
            ("App::PropertyInteger", "NRowsSkipped", "Rows of the file that were not usable",
             READ_ONLY),
            ("App::PropertyFloat", "MeanSNR", "Mean SNR of the points", READ_ONLY),
            ("App::PropertyString", "LoadedSignature",
             "Path, size and time of the file last read", HIDDEN)))

    def execute(self, obj):
        if obj.SourceFile and os.path.exists(obj.SourceFile):
            signature = file_signature(obj.SourceFile)
            if signature != obj.LoadedSignature:
                store_pointset(obj, pipeline.load_points(obj.SourceFile))
                obj.LoadedSignature = signature
        elif obj.SourceFile:
            raise InputError("%s: no such point file" % obj.SourceFile)


def _column_property(name):
    return "Column_" + "".join(c if c.isalnum() else "_" for c in name)


def store_pointset(obj, pointset):
    xyz = np.asarray(pointset.xyz, dtype=float)
    if xyz.ndim != 2 or xyz.shape[1] != 3 or len(xyz) == 0:
        raise InputError("%s: points must be a non-empty list of x, y, z"
                         % (pointset.source or obj.Label))
    obj.Coordinates = xyz.ravel().tolist()
    obj.Points = points_kernel(xyz)
    snr = pointset.snr
    obj.SNR = [] if snr is None else np.asarray(snr, dtype=float).tolist()
    obj.MeanSNR = 0.0 if snr is None or len(snr) == 0 else float(np.mean(snr))
    names = []
    for name, values in pointset.columns.items():
        values = np.asarray(values)
        if values.dtype.kind not in "biuf" or len(values) != len(xyz):
            continue
        prop = _column_property(name)
        add_property(obj, "App::PropertyFloatList", prop, "Columns", "Input column %s" % name,
                     hidden=True)
        setattr(obj, prop, values.astype(float).tolist())
        names.append(name)
    obj.ColumnNames = names
    obj.NPoints = len(xyz)
    obj.NRowsSkipped = int(pointset.n_rows_skipped)


def pointset_of(obj):
    """The PointSet a Measurement holds, exactly as it was stored."""
    xyz = np.asarray(obj.Coordinates, dtype=float).reshape(-1, 3)
    snr = np.asarray(obj.SNR, dtype=float) if len(obj.SNR) else None
    columns = {}
    for name in obj.ColumnNames:
        columns[name] = np.asarray(getattr(obj, _column_property(name)), dtype=float)
    source = obj.SourceFile or obj.Label
    return PointSet(xyz=xyz, snr=snr, columns=columns, n_rows_skipped=obj.NRowsSkipped,
                    source=source)


def make_measurement(doc, pointset, name="Measurement", source_file=""):
    """A Measurement holding `pointset`; `source_file` (optional) is re-read on recompute when
    that file changes."""
    with building(doc, "Measurement"):
        obj = doc.addObject("Points::FeaturePython", name)
        Measurement(obj)
        store_pointset(obj, pointset)
        if source_file:
            obj.SourceFile = source_file
            obj.LoadedSignature = file_signature(source_file)
        obj.purgeTouched()
        attach_view(obj)
    return obj
