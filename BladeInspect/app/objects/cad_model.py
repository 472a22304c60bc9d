"""CadModel: a nominal read from a CAD file as a document object."""

import os

from ...cad.load import load_shape
from ...cad.rotor67 import make_rotor67_blade
from ...core.errors import InputError
from .base import Proxy, add_property, attach_view, building, file_signature
from .nominal import roles_to_map


class CadModel(Proxy):
    """A nominal read from a CAD file (STEP/IGES/BREP/FCStd), re-read when the path changes."""
    Type = "BladeInspect::CadModel"

    def add_properties(self, obj):
        add_property(obj, "App::PropertyFile", "SourceFile", "CAD",
                     "CAD file of the nominal blade")
        add_property(obj, "App::PropertyMap", "FaceRoles", "CAD",
                     "Face indices of each role (empty: unknown)")
        add_property(obj, "App::PropertyString", "LoadedSignature", "CAD",
                     "Path, size and time of the file last read", hidden=True)

    def execute(self, obj):
        path = obj.SourceFile
        if not path:
            raise InputError("%s: no CAD file given" % obj.Label)
        if not os.path.exists(path):
            raise InputError("%s: no such CAD file" % path)
        signature = file_signature(path)
        if signature == obj.LoadedSignature and not obj.Shape.isNull():
            return
        if path.lower().endswith(".dat"):
            # A blade section table (NASA Rotor 67 format), lofted into faces with roles.
            model = make_rotor67_blade(path)
            obj.Shape = model.shape
            obj.FaceRoles = roles_to_map(model.roles)
        else:
            obj.Shape = load_shape(path)
            obj.FaceRoles = {}
        obj.LoadedSignature = signature


def make_cad_model(doc, path, name="Nominal"):
    with building(doc, "Load CAD"):
        obj = doc.addObject("Part::FeaturePython", name)
        CadModel(obj)
        obj.SourceFile = path
        obj.Label = os.path.splitext(os.path.basename(path))[0]
        obj.Proxy.execute(obj)   # raises the loader's InputError, recompute() would swallow it
        obj.purgeTouched()
        attach_view(obj)
    return obj
