"""DemoBlade: the built-in parametric demo blade as a document object."""

import dataclasses

from ...cad import demo_blade as blade
from .base import Proxy, add_property, attach_view, building, check_recomputed
from .nominal import roles_to_map


class DemoBlade(Proxy):
    """The built-in parametric demo blade: BladeParams as properties, rebuilt when one changes."""
    Type = "BladeInspect::DemoBlade"

    def add_properties(self, obj):
        kinds = {float: "App::PropertyFloat", int: "App::PropertyInteger",
                 bool: "App::PropertyBool"}
        defaults = blade.BladeParams()
        for field in dataclasses.fields(blade.BladeParams):
            value = getattr(defaults, field.name)
            kind = kinds.get(type(value))
            if kind is None:
                continue
            if field.name not in obj.PropertiesList:
                obj.addProperty(kind, field.name, "Blade", "BladeParams.%s" % field.name)
                setattr(obj, field.name, value)
        add_property(obj, "App::PropertyMap", "FaceRoles", "Blade",
                     "Face indices of each role (suction, pressure, leading_edge, ...)",
                     read_only=True)
        add_property(obj, "App::PropertyBool", "RootBlock", "Blade",
                     "On a root block with three datum faces (--cad demo:root-block)")

    def params(self, obj):
        names = [f.name for f in dataclasses.fields(blade.BladeParams)]
        return blade.BladeParams(**{n: getattr(obj, n) for n in names
                                    if n in obj.PropertiesList})

    def execute(self, obj):
        model = blade.make_demo_blade(self.params(obj), root_block=obj.RootBlock)
        obj.Shape = model.shape
        obj.FaceRoles = roles_to_map(model.roles)


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
        check_recomputed(obj)
        attach_view(obj)
    return obj
