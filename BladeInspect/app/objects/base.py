"""What every BladeInspect document object shares: the proxy base class, adding properties,
input signatures, the undoable building step, and the hook through which the gui layer gives
new and restored objects their view providers (no GUI imports here)."""

import contextlib
import hashlib
import os

import numpy as np

import FreeCAD

from ...core.errors import InputError

_view_provider_hook = None


def set_view_provider_hook(hook):
    """hook(obj) gives a document object its view provider; set by BladeInspect.gui."""
    global _view_provider_hook
    _view_provider_hook = hook


def attach_view(obj):
    if _view_provider_hook is not None and FreeCAD.GuiUp and obj.ViewObject is not None:
        _view_provider_hook(obj)


# ---------------------------------------------------------------- properties

def add_property(obj, kind, name, group, tooltip, read_only=False, hidden=False):
    """Add a property unless present (documents from older versions gain new ones on restore)."""
    if name not in obj.PropertiesList:
        obj.addProperty(kind, name, group, tooltip)
    modes = (["ReadOnly"] if read_only else []) + (["Hidden"] if hidden else [])
    if modes:
        obj.setEditorMode(name, modes)


READ_ONLY, HIDDEN = "read only", "hidden"


def add_table(obj, group, rows):
    """add_property for each row (kind, name, tooltip[, READ_ONLY or HIDDEN]) of one group."""
    for kind, name, tip, *mode in rows:
        add_property(obj, kind, name, group, tip, read_only=READ_ONLY in mode,
                     hidden=HIDDEN in mode)


def proxy_type(obj):
    """The BladeInspect type of a document object ("BladeInspect::Measurement", ...) or None."""
    proxy = getattr(obj, "Proxy", None)
    return getattr(proxy, "Type", None)


def find_objects(doc, type_name):
    return [o for o in doc.Objects if proxy_type(o) == type_name]


# ---------------------------------------------------------------- building

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


def finish(obj):
    """An object just made from its inputs: its input signature stored, not touched (nothing
    to recompute), its view provider given."""
    obj.InputSignature = obj.Proxy.signature(obj)
    obj.purgeTouched()
    attach_view(obj)


def check_recomputed(obj):
    """recompute() reports a failing execute() only through the object's state."""
    if "Invalid" in obj.State or "Error" in obj.State:
        raise InputError("%s: %s" % (obj.Label, obj.getStatusString()))


# ---------------------------------------------------------------- the proxy

class Stateless:
    """A proxy (document object or view provider) that keeps no state of its own: everything
    lives in properties, so the document stores nothing for the proxy itself. FreeCAD 1.0 asks
    a proxy for that state through dumps/loads, FreeCAD 0.20 through
    __getstate__/__setstate__."""

    def dumps(self):
        return None

    def loads(self, state):
        return None

    def __getstate__(self):
        return self.dumps()

    def __setstate__(self, state):
        self.loads(state)


class Proxy(Stateless):
    """Common plumbing of the document objects (state: none, Stateless).

    A document records each proxy's module and class name and imports them on opening: a
    class keeps its name, and the package app.objects exports it too (see its docstring)."""
    Type = None

    def __init__(self, obj):
        obj.Proxy = self
        self.add_properties(obj)

    def add_properties(self, obj):
        raise NotImplementedError

    def onDocumentRestored(self, obj):
        self.add_properties(obj)
        attach_view(obj)


# ---------------------------------------------------------------- signatures

def signature(*parts):
    """A digest of the inputs an object's result was made from."""
    h = hashlib.sha1()
    for part in parts:
        if isinstance(part, np.ndarray):
            h.update(np.ascontiguousarray(part).tobytes())
        else:
            h.update(repr(part).encode())
    return h.hexdigest()


def file_signature(path):
    st = os.stat(path)
    return "%s|%d|%d" % (os.path.abspath(path), st.st_size, st.st_mtime_ns)


def shape_signature(shape):
    """Fingerprint of a shape's geometry in its placed position. Not its BREP text: a
    recompute adds an identity location to it without changing anything."""
    parts = []
    for face in shape.Faces:
        u0, u1, v0, v1 = face.ParameterRange
        probes = [face.valueAt(u0 + (u1 - u0) * a, v0 + (v1 - v0) * b)
                  for a, b in ((0.5, 0.5), (0.25, 0.75), (0.75, 0.25))]
        parts.append((type(face.Surface).__name__, round(face.Area, 9),
                      [round(c, 9) for p in probes for c in (p.x, p.y, p.z)]))
    return signature(parts)


def points_kernel(xyz):
    """The Points kernel of (N, 3) coordinates (single precision: for display)."""
    import Points
    return Points.Points(list(map(tuple, np.asarray(xyz, dtype=float).tolist())))
