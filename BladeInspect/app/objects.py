"""BladeInspect's document objects: FeaturePython proxies that keep each stage's output in the
document, so it is saved in the .FCStd and recomputed when an input changes.

  DemoBlade / CadModel   the nominal (Part shape, face roles)
  Measurement            measured points (double precision) + SNR + extra columns
  Reconstruction         section curves and lofted surfaces of a measurement (Part geometry)
  Registration           pose of a measurement on a nominal, statistics, uncertainty, deviations
  DeviationMap           the registered points coloured by deviation, with a legend

The make_* functions build them from plain pipeline data; the headless report writer and the GUI
commands use the same functions. Long computations run in the GUI commands with progress and
cancel; an object's execute() repeats a stage only when its inputs really changed (an input
signature is stored), so opening a document or recomputing is cheap.

No GUI imports here: the gui layer registers a hook (set_view_provider_hook) that gives new and
restored objects their view providers when FreeCAD.GuiUp.
"""

import contextlib
import dataclasses
import hashlib
import json
import os

import numpy as np

import FreeCAD

from ..core.contracts import json_default
from ..cad import demo_blade, loft
from ..cad.load import load_shape
from ..cad.nominal import nominal_from_shape
from ..cad.rotor67 import make_rotor67_blade
from ..core import colourmap
from ..core.errors import InputError
from ..core.pointio import PointSet
from ..inspection import pipeline
from ..inspection.result import RegistrationResult
from . import registration_fit

_view_provider_hook = None


def set_view_provider_hook(hook):
    """hook(obj) gives a document object its view provider; set by BladeInspect.gui."""
    global _view_provider_hook
    _view_provider_hook = hook


def _attach_view(obj):
    if _view_provider_hook is not None and FreeCAD.GuiUp and obj.ViewObject is not None:
        _view_provider_hook(obj)


# ---------------------------------------------------------------- helpers

def _add(obj, kind, name, group, tooltip, read_only=False, hidden=False):
    """Add a property unless present (documents from older versions gain new ones on restore)."""
    if name not in obj.PropertiesList:
        obj.addProperty(kind, name, group, tooltip)
    modes = (["ReadOnly"] if read_only else []) + (["Hidden"] if hidden else [])
    if modes:
        obj.setEditorMode(name, modes)


READ_ONLY, HIDDEN = "read only", "hidden"


def _add_table(obj, group, rows):
    """_add for each row (kind, name, tooltip[, READ_ONLY or HIDDEN]) of one group."""
    for kind, name, tip, *mode in rows:
        _add(obj, kind, name, group, tip, read_only=READ_ONLY in mode, hidden=HIDDEN in mode)


def proxy_type(obj):
    """The BladeInspect type of a document object ("BladeInspect::Measurement", ...) or None."""
    proxy = getattr(obj, "Proxy", None)
    return getattr(proxy, "Type", None)


def find_objects(doc, type_name):
    return [o for o in doc.Objects if proxy_type(o) == type_name]


_BUILDING = set()


@contextlib.contextmanager
def building(doc, title):
    """Create objects as one undoable step; on any error remove whatever was created, so a
    failure never leaves half-built objects (undo is off in headless documents, so the objects
    are removed by name rather than by aborting the transaction alone). Nested uses join the
    outermost step."""
    if doc.Name in _BUILDING:
        yield
        return
    before = set(o.Name for o in doc.Objects)
    _BUILDING.add(doc.Name)
    doc.openTransaction(title)
    try:
        yield
    except BaseException:
        doc.abortTransaction()
        for name in [o.Name for o in doc.Objects if o.Name not in before]:
            if doc.getObject(name) is not None:
                doc.removeObject(name)
        raise
    else:
        doc.commitTransaction()
    finally:
        _BUILDING.discard(doc.Name)


class _Proxy:
    """Common plumbing. Proxies keep no state of their own: everything lives in properties, so
    nothing needs pickling (FreeCAD 0.20 calls __getstate__/__setstate__)."""
    Type = None

    def __init__(self, obj):
        obj.Proxy = self
        self.add_properties(obj)

    def add_properties(self, obj):
        raise NotImplementedError

    def onDocumentRestored(self, obj):
        self.add_properties(obj)
        _attach_view(obj)

    def __getstate__(self):
        return None

    def __setstate__(self, state):
        return None


def _points_kernel(xyz):
    import Points
    return Points.Points(list(map(tuple, np.asarray(xyz, dtype=float).tolist())))


def _signature(*parts):
    h = hashlib.sha1()
    for part in parts:
        if isinstance(part, np.ndarray):
            h.update(np.ascontiguousarray(part).tobytes())
        else:
            h.update(repr(part).encode())
    return h.hexdigest()


def _file_signature(path):
    st = os.stat(path)
    return "%s|%d|%d" % (os.path.abspath(path), st.st_size, st.st_mtime_ns)


def _shape_signature(shape):
    """Fingerprint of a shape's geometry in its placed position. Not its BREP text: a
    recompute adds an identity location to it without changing anything."""
    parts = []
    for face in shape.Faces:
        u0, u1, v0, v1 = face.ParameterRange
        probes = [face.valueAt(u0 + (u1 - u0) * a, v0 + (v1 - v0) * b)
                  for a, b in ((0.5, 0.5), (0.25, 0.75), (0.75, 0.25))]
        parts.append((type(face.Surface).__name__, round(face.Area, 9),
                      [round(c, 9) for p in probes for c in (p.x, p.y, p.z)]))
    return _signature(parts)


# ---------------------------------------------------------------- nominal

def _roles_to_map(roles):
    return {name: " ".join(str(int(i)) for i in faces) for name, faces in (roles or {}).items()}


def _roles_from_map(mapping):
    return {name: [int(i) for i in text.split()] for name, text in dict(mapping).items()}


class DemoBlade(_Proxy):
    """The built-in parametric demo blade: BladeParams as properties, rebuilt when one changes."""
    Type = "BladeInspect::DemoBlade"

    def add_properties(self, obj):
        kinds = {float: "App::PropertyFloat", int: "App::PropertyInteger",
                 bool: "App::PropertyBool"}
        defaults = demo_blade.BladeParams()
        for field in dataclasses.fields(demo_blade.BladeParams):
            value = getattr(defaults, field.name)
            kind = kinds.get(type(value))
            if kind is None:
                continue
            if field.name not in obj.PropertiesList:
                obj.addProperty(kind, field.name, "Blade", "BladeParams.%s" % field.name)
                setattr(obj, field.name, value)
        _add(obj, "App::PropertyMap", "FaceRoles", "Blade",
             "Face indices of each role (suction, pressure, leading_edge, ...)", read_only=True)
        _add(obj, "App::PropertyBool", "RootBlock", "Blade",
             "On a root block with three datum faces (--cad demo:root-block)")

    def params(self, obj):
        names = [f.name for f in dataclasses.fields(demo_blade.BladeParams)]
        return demo_blade.BladeParams(**{n: getattr(obj, n) for n in names
                                         if n in obj.PropertiesList})

    def execute(self, obj):
        model = demo_blade.make_demo_blade(self.params(obj), root_block=obj.RootBlock)
        obj.Shape = model.shape
        obj.FaceRoles = _roles_to_map(model.roles)


class CadModel(_Proxy):
    """A nominal read from a CAD file (STEP/IGES/BREP/FCStd), re-read when the path changes."""
    Type = "BladeInspect::CadModel"

    def add_properties(self, obj):
        _add(obj, "App::PropertyFile", "SourceFile", "CAD", "CAD file of the nominal blade")
        _add(obj, "App::PropertyMap", "FaceRoles", "CAD",
             "Face indices of each role (empty: unknown)")
        _add(obj, "App::PropertyString", "LoadedSignature", "CAD",
             "Path, size and time of the file last read", hidden=True)

    def execute(self, obj):
        path = obj.SourceFile
        if not path:
            raise InputError("%s: no CAD file given" % obj.Label)
        if not os.path.exists(path):
            raise InputError("%s: no such CAD file" % path)
        signature = _file_signature(path)
        if signature == obj.LoadedSignature and not obj.Shape.isNull():
            return
        if path.lower().endswith(".dat"):
            # A blade section table (NASA Rotor 67 format), lofted into faces with roles.
            model = make_rotor67_blade(path)
            obj.Shape = model.shape
            obj.FaceRoles = _roles_to_map(model.roles)
        else:
            obj.Shape = load_shape(path)
            obj.FaceRoles = {}
        obj.LoadedSignature = signature


_NOMINAL_CACHE = {}


def nominal_of(obj):
    """The pipeline's Nominal of a document object's shape (any Part feature; face roles from
    its FaceRoles when it has them). Cached by shape content: building one samples every face."""
    shape = obj.Shape
    if shape.isNull() or not shape.Faces:
        raise InputError("%s: the nominal has no faces" % obj.Label)
    roles = _roles_from_map(obj.FaceRoles) if "FaceRoles" in obj.PropertiesList else None
    key = (_shape_signature(shape), json.dumps(roles, sort_keys=True))
    if key not in _NOMINAL_CACHE:
        _NOMINAL_CACHE.clear()
        _NOMINAL_CACHE[key] = nominal_from_shape(shape, roles=roles or None)
    return _NOMINAL_CACHE[key]


def make_demo_blade(doc, params=None, name="DemoBlade", root_block=False):
    with building(doc, "Demo blade"):
        obj = doc.addObject("Part::FeaturePython", name)
        DemoBlade(obj)
        obj.RootBlock = bool(root_block)
        if params is not None:
            for field in dataclasses.fields(params):
                if field.name in obj.PropertiesList:
                    setattr(obj, field.name, getattr(params, field.name))
        obj.recompute()
        _check_recomputed(obj)
        _attach_view(obj)
    return obj


def make_cad_model(doc, path, name="Nominal"):
    with building(doc, "Load CAD"):
        obj = doc.addObject("Part::FeaturePython", name)
        CadModel(obj)
        obj.SourceFile = path
        obj.Label = os.path.splitext(os.path.basename(path))[0]
        obj.Proxy.execute(obj)   # raises the loader's InputError, recompute() would swallow it
        obj.purgeTouched()
        _attach_view(obj)
    return obj


def _finish(obj):
    """An object just made from its inputs: its input signature stored, not touched (nothing
    to recompute), its view provider given."""
    obj.InputSignature = obj.Proxy.signature(obj)
    obj.purgeTouched()
    _attach_view(obj)


def _check_recomputed(obj):
    """recompute() reports a failing execute() only through the object's state."""
    if "Invalid" in obj.State or "Error" in obj.State:
        raise InputError("%s: %s" % (obj.Label, obj.getStatusString()))


# ---------------------------------------------------------------- measurement

class Measurement(_Proxy):
    """Measured points with their SNR and extra columns (section, angle_deg, ...). Coordinates
    are kept in double precision in `Coordinates`; the `Points` kernel (single precision) is
    for display only."""
    Type = "BladeInspect::Measurement"

    def add_properties(self, obj):
        _add_table(obj, "Measurement", (
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
            signature = _file_signature(obj.SourceFile)
            if signature != obj.LoadedSignature:
                store_pointset(obj, pipeline.load_points(obj.SourceFile))
                obj.LoadedSignature = signature
        elif obj.SourceFile:
            raise InputError("%s: no such point file" % obj.SourceFile)


def store_pointset(obj, pointset):
    xyz = np.asarray(pointset.xyz, dtype=float)
    if xyz.ndim != 2 or xyz.shape[1] != 3 or len(xyz) == 0:
        raise InputError("%s: points must be a non-empty list of x, y, z"
                         % (pointset.source or obj.Label))
    obj.Coordinates = xyz.ravel().tolist()
    obj.Points = _points_kernel(xyz)
    snr = pointset.snr
    obj.SNR = [] if snr is None else np.asarray(snr, dtype=float).tolist()
    obj.MeanSNR = 0.0 if snr is None or len(snr) == 0 else float(np.mean(snr))
    names = []
    for name, values in pointset.columns.items():
        values = np.asarray(values)
        if values.dtype.kind not in "biuf" or len(values) != len(xyz):
            continue
        prop = "Column_" + "".join(c if c.isalnum() else "_" for c in name)
        _add(obj, "App::PropertyFloatList", prop, "Columns", "Input column %s" % name,
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
        prop = "Column_" + "".join(c if c.isalnum() else "_" for c in name)
        columns[name] = np.asarray(getattr(obj, prop), dtype=float)
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
            obj.LoadedSignature = _file_signature(source_file)
        obj.purgeTouched()
        _attach_view(obj)
    return obj


# ---------------------------------------------------------------- reconstruction

class Reconstruction(_Proxy):
    """Cubic B-spline section curves and the lofted surfaces through them (paper 3.1.2)."""
    Type = "BladeInspect::Reconstruction"

    def add_properties(self, obj):
        _add_table(obj, "Reconstruction", (
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
        return _signature(np.asarray(obj.Measurement.Coordinates),
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
        _finish(obj)
    return obj


# ---------------------------------------------------------------- registration

def _matrix(T):
    T = np.asarray(T, dtype=float)
    return FreeCAD.Matrix(*T.ravel().tolist())


def matrix_array(m):
    return np.array(m.A, dtype=float).reshape(4, 4)


class Registration(_Proxy):
    """Pose of a measurement on a nominal (measured -> CAD), its uncertainty, the statistics and
    the signed deviation of every point. Re-registers when the measurement, the nominal's shape
    or the seed change; without linked inputs it keeps the result it was made from."""
    Type = "BladeInspect::Registration"

    def add_properties(self, obj):
        g = "Inputs"
        _add(obj, "App::PropertyLink", "Measurement", g, "Measured points")
        _add(obj, "App::PropertyLink", "Nominal", g, "Nominal CAD (a Part feature)")
        _add(obj, "App::PropertyInteger", "Seed", g, "Random seed of the coarse stage")
        registration_fit.add_properties(obj, _add)   # hook: the fit (issue 16)
        g = "Pose"
        _add(obj, "App::PropertyPlacement", "Pose", g, "Measured -> CAD rigid transform",
             read_only=True)
        _add(obj, "App::PropertyMatrix", "MeasuredToCad", g,
             "Measured -> CAD 4x4 matrix (as in result.json)", read_only=True)
        _add(obj, "App::PropertyFloat", "PoseUncertaintyMm", g,
             "1 sigma displacement at the worst corner of the CAD's bounding box, mm",
             read_only=True)
        _add(obj, "App::PropertyFloatList", "PoseCovariance", g,
             "6x6 covariance, row-major: translation mm, rotation rad, about CovarianceCenter",
             read_only=True)
        _add(obj, "App::PropertyVector", "CovarianceCenter", g,
             "Point the covariance's rotation is about, CAD frame, mm", read_only=True)
        _add(obj, "App::PropertyVector", "TranslationSigmaMm", g,
             "1 sigma of the translation along x, y, z, mm", read_only=True)
        _add(obj, "App::PropertyVector", "RotationSigmaDeg", g,
             "1 sigma of the rotation about x, y, z, degrees", read_only=True)
        g = "Statistics"
        for name, tip in (("RmsMm", "RMS of the inliers' deviations, mm"),
                          ("DeviationMinMm", "Smallest signed deviation, mm"),
                          ("DeviationMaxMm", "Largest signed deviation, mm"),
                          ("DeviationMeanMm", "Mean deviation, mm"),
                          ("DeviationStdMm", "Standard deviation about the mean, mm"),
                          ("PctWithin1Sigma", "% of points within mean +- 1 sigma"),
                          ("PctWithin3Sigma", "% of points within mean +- 3 sigma")):
            _add(obj, "App::PropertyFloat", name, g, tip, read_only=True)
        _add(obj, "App::PropertyInteger", "NPoints", g, "Registered points", read_only=True)
        _add(obj, "App::PropertyInteger", "NInliers", g, "Points the fit used", read_only=True)
        _add(obj, "App::PropertyStringList", "Warnings", g, "Warnings of the pipeline",
             read_only=True)
        _add(obj, "App::PropertyString", "StatisticsJson", g,
             "deviation statistics with the histogram, as in result.json", hidden=True)
        _add(obj, "App::PropertyString", "CoarseJson", g,
             "coarse stage (PCA candidates), as in result.json", hidden=True)
        g = "Deviations"
        _add(obj, "App::PropertyFloatList", "PointsCad", g,
             "Registered points in the CAD frame, flattened x, y, z, mm", hidden=True)
        _add(obj, "App::PropertyFloatList", "Deviation", g,
             "Signed deviation of every point, + outside material, mm", hidden=True)
        _add(obj, "App::PropertyIntegerList", "Inlier", g, "1 where the fit used the point",
             hidden=True)
        _add(obj, "App::PropertyString", "InputSignature", g,
             "Signature of the inputs the result was made from", hidden=True)

    def signature(self, obj):
        if obj.Measurement is None or obj.Nominal is None:
            return ""
        m = obj.Measurement
        return _signature(np.asarray(m.Coordinates), np.asarray(m.SNR),
                          _shape_signature(obj.Nominal.Shape), obj.Seed,
                          *registration_fit.signature_part(obj))   # hook: issue 16

    def execute(self, obj):
        signature = self.signature(obj)
        if not signature or signature == obj.InputSignature:
            return
        nominal = nominal_of(obj.Nominal)
        result = pipeline.register(nominal, pointset_of(obj.Measurement), seed=obj.Seed,
                                   **registration_fit.register_options(obj))  # issue 16
        registration_fit.refit(obj, result, nominal)   # hook: issue 16
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
    registration_fit.store(obj, result)   # hook: issue 16


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
        if fit_choice is not None:   # hook: issue 16
            registration_fit.set_choice(obj, fit_choice)
        store_registration(obj, result)
        _finish(obj)
    return obj


def registration_points(obj):
    """(points in the CAD frame (N, 3), deviation (N,), inlier (N,) bool) of a Registration."""
    return (np.asarray(obj.PointsCad, dtype=float).reshape(-1, 3),
            np.asarray(obj.Deviation, dtype=float),
            np.asarray(obj.Inlier, dtype=bool))


# ---------------------------------------------------------------- deviation map

class DeviationMap(_Proxy):
    """The registered points coloured by signed deviation (saturating at +-Limit), shown per
    point through the `Color` list, with the legend's values and colours for the view."""
    Type = "BladeInspect::DeviationMap"

    def add_properties(self, obj):
        g = "Deviation map"
        _add(obj, "App::PropertyLink", "Registration", g, "Registration whose deviations are shown")
        _add(obj, "App::PropertyFloat", "Limit", g,
             "Deviation at which the colours saturate (blue -Limit, green 0, red +Limit), mm")
        _add(obj, "App::PropertyColorList", "Color", g, "Colour of every point", hidden=True)
        _add(obj, "App::PropertyFloatList", "Deviation", g, "Signed deviation of every point, mm",
             hidden=True)
        _add(obj, "App::PropertyFloatList", "LegendValues", g, "Legend tick values, mm",
             read_only=True)
        _add(obj, "App::PropertyColorList", "LegendColors", g, "Colour at each legend tick",
             hidden=True)
        _add(obj, "App::PropertyInteger", "NPoints", g, "Points shown", read_only=True)

    def execute(self, obj):
        if obj.Registration is None:
            raise InputError("%s: no registration linked" % obj.Label)
        if obj.Limit <= 0:
            raise InputError("%s: Limit must be positive, got %g" % (obj.Label, obj.Limit))
        points, deviation, _ = registration_points(obj.Registration)
        obj.Points = _points_kernel(points)
        obj.Deviation = deviation.tolist()
        obj.Color = [tuple(c) for c in colourmap.deviation_colours(deviation, obj.Limit).tolist()]
        values, colours = colourmap.legend_ticks(obj.Limit)
        obj.LegendValues = values.tolist()
        obj.LegendColors = [tuple(c) for c in colours.tolist()]
        obj.NPoints = len(deviation)


def make_deviation_map(doc, registration, limit, name="DeviationMap"):
    """A DeviationMap of `registration`: a Registration document object, or a
    RegistrationResult (a Registration object holding it is made first)."""
    with building(doc, "Deviation map"):
        if proxy_type(registration) != Registration.Type:
            registration = make_registration(doc, registration)
        obj = doc.addObject("Points::FeaturePython", name)
        DeviationMap(obj)
        obj.Registration = registration
        obj.Limit = float(limit)
        obj.Proxy.execute(obj)
        obj.purgeTouched()
        _attach_view(obj)
    return obj


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
    registration_fit.restore(obj, result)   # hook: issue 16, the weights used
    return result


def make_section_profiles(doc, table, registration=None, name="SectionProfiles"):
    """The nominal section profiles of a section table (inspection.sections) as Part polylines, one
    compound, for showing where the sections were cut. A snapshot: made again by the command."""
    import Part
    edges = []
    labels = []
    for section in table.sections:
        if section.profile is None:
            continue
        for poly in section.profile.polylines:
            poly = np.asarray(poly, dtype=float)
            if len(poly) >= 2:
                edges.append(Part.makePolygon([FreeCAD.Vector(*p) for p in poly]))
        labels.append(section.label)
    if not edges:
        raise InputError("section analysis: no section plane cuts the nominal")
    with building(doc, "Section profiles"):
        obj = doc.addObject("Part::Feature", name)
        obj.Shape = Part.Compound(edges)
        obj.addProperty("App::PropertyStringList", "Sections", "Sections",
                        "Labels of the sections cut")
        obj.Sections = labels
        if registration is not None:
            obj.addProperty("App::PropertyLink", "Registration", "Sections",
                            "Registration the sections were analysed for")
            obj.Registration = registration
        # What was analysed is a record, not an input: editing it would not recut the sections.
        for prop in ("Sections", "Registration"):
            if prop in obj.PropertiesList:
                obj.setEditorMode(prop, ["ReadOnly"])
        if obj.ViewObject is not None:
            obj.ViewObject.LineColor = (0.8, 0.1, 0.1)
            obj.ViewObject.LineWidth = 3
    return obj
