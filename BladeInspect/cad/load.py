"""Reading CAD shapes (STEP, IGES, BREP, FreeCAD documents) and point files of any kind.

Every way a file can be unusable ends in one InputError "<path>: <problem>"; OCC's own
exceptions carry C++ class names and dict payloads that mean nothing to a user.
"""
import os

import numpy as np

import FreeCAD
import Part

from ..core.contracts import BUILTIN_CADS
from ..core.errors import InputError

SHAPE_EXTENSIONS = (".step", ".stp", ".iges", ".igs", ".brep", ".brp")
DOCUMENT_EXTENSIONS = (".fcstd",)
POINTS_MODULE_EXTENSIONS = (".ply", ".pcd")


def _check_file(path, kinds):
    if not os.path.exists(path):
        raise InputError("%s: no such file" % path)
    if os.path.isdir(path):
        raise InputError("%s: is a folder, not a %s file" % (path, kinds))
    if os.path.getsize(path) == 0:
        raise InputError("%s: the file is empty" % path)


def load_shape(path):
    """The shape in a CAD file: .step/.stp/.iges/.igs/.brep/.brp, or the visible Part shapes of
    an .FCStd document (opened without a GUI and closed again). Must have faces."""
    path = str(path)
    ext = os.path.splitext(path)[1].lower()
    if ext not in SHAPE_EXTENSIONS + DOCUMENT_EXTENSIONS:
        raise InputError("%s: unsupported CAD file type '%s' (use .step, .stp, .iges, .igs, "
                         ".brep, .brp or .FCStd)" % (path, ext))
    _check_file(path, "CAD")
    if ext in DOCUMENT_EXTENSIONS:
        shape = _document_shape(path)
    else:
        shape = Part.Shape()
        try:
            shape.read(path)
        except Exception:
            raise InputError("%s: not a readable %s file" % (path, ext[1:].upper())) from None
    if shape.isNull() or not shape.Faces:
        raise InputError("%s: the file holds no faces (a blade CAD needs its surfaces)" % path)
    return shape


def _document_shape(path):
    """Visible Part shapes of a FreeCAD document: one as it is, several as a compound."""
    before = set(FreeCAD.listDocuments())
    already_open = [d for d in FreeCAD.listDocuments().values()
                    if os.path.abspath(d.FileName) == os.path.abspath(path)]
    try:
        doc = already_open[0] if already_open else FreeCAD.openDocument(path, True)
        shapes = [_placed_shape(obj) for obj in doc.Objects if _is_visible_solid_part(obj)]
    except Exception:
        raise InputError("%s: not a readable FreeCAD document" % path) from None
    finally:
        # openDocument keeps a half-loaded document alive on failure: close whatever it made,
        # never a document the user had open already.
        for name in set(FreeCAD.listDocuments()) - before:
            FreeCAD.closeDocument(name)
    if not shapes:
        raise InputError("%s: no visible object with faces in the document" % path)
    return shapes[0] if len(shapes) == 1 else Part.Compound(shapes)


def _is_visible_solid_part(obj):
    """A Part feature with faces shown in the document, counted once: a PartDesign body
    stands for the features inside it, and a hidden container hides what it holds."""
    if not obj.isDerivedFrom("Part::Feature"):
        return False
    shape = obj.Shape
    if shape.isNull() or not shape.Faces:
        return False
    parent = obj.getParentGeoFeatureGroup()
    if parent is not None and parent.isDerivedFrom("PartDesign::Body"):
        return False
    while obj is not None:
        if not getattr(obj, "Visibility", True):
            return False
        obj = obj.getParentGeoFeatureGroup()
    return True


def _placed_shape(obj):
    """The object's shape where the document shows it (inside containers' placements)."""
    shape = obj.Shape.copy()
    shape.Placement = obj.getGlobalPlacement()
    return shape


def read_points_any(path):
    """A PointSet from .csv/.xyz/.asc/.txt (the core reader) or .ply/.pcd (FreeCAD Points)."""
    from ..core import pointio
    path = str(path)
    ext = os.path.splitext(path)[1].lower()
    if ext not in POINTS_MODULE_EXTENSIONS:
        return pointio.read_points(path)
    _check_file(path, "point")
    import Points
    before = set(FreeCAD.listDocuments())
    doc = FreeCAD.newDocument("BladeInspectPointsImport", hidden=True, temp=True)
    try:
        try:
            Points.insert(path, doc.Name)
        except Exception:
            raise InputError("%s: not a readable %s point file" % (path, ext[1:].upper())) \
                from None
        clouds = [o.Points for o in doc.Objects if hasattr(o, "Points")]
        xyz = np.array([[p.x, p.y, p.z] for cloud in clouds for p in cloud.Points],
                       dtype=float).reshape(-1, 3)
    finally:
        for name in set(FreeCAD.listDocuments()) - before:
            FreeCAD.closeDocument(name)
    usable = np.all(np.isfinite(xyz), axis=1)
    if usable.sum() < pointio.MIN_POINTS:
        raise InputError("%s: %d usable points, at least %d needed"
                         % (path, int(usable.sum()), pointio.MIN_POINTS))
    return pointio.PointSet(xyz=xyz[usable], snr=None, columns={},
                            n_rows_skipped=int((~usable).sum()), source=path)



def builtin_cad(cad_path):
    """make_demo_blade's keyword arguments when ``cad_path`` is None or names a built-in part
    (BUILTIN_CADS; a file of that name wins), else None."""
    if cad_path is None:
        return dict(BUILTIN_CADS["demo"])
    if cad_path in BUILTIN_CADS and not os.path.exists(cad_path):
        return dict(BUILTIN_CADS[cad_path])
    return None


def load_nominal(cad_path=None, sample_spacing=None, flip_faces=()):
    """The nominal geometry every command measures against: a CAD file, a blade section table
    (.dat, the NASA Rotor 67 format, lofted into B-spline faces), or the built-in demo blade
    when ``cad_path`` is None or names it (BUILTIN_CADS; a file of that name wins).
    ``flip_faces``: indices of faces whose outward side the user
    reverses (``--flip-face``, see cad.orient)."""
    from .nominal import nominal_from_shape
    builtin = builtin_cad(cad_path)
    if builtin is not None:
        from .demo_blade import make_demo_blade
        model = make_demo_blade(**builtin)
        return nominal_from_shape(model.shape, roles=model.roles, sample_spacing=sample_spacing,
                                  flip_faces=flip_faces)
    if cad_path.lower().endswith(".dat"):
        _check_file(cad_path, "section table")
        from .rotor67 import make_rotor67_blade
        model = make_rotor67_blade(cad_path)
        return nominal_from_shape(model.shape, roles=model.roles, sample_spacing=sample_spacing,
                                  flip_faces=flip_faces)
    return nominal_from_shape(load_shape(cad_path), sample_spacing=sample_spacing,
                              flip_faces=flip_faces)
