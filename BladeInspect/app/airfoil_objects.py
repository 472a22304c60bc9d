"""The airfoil analysis in the document: per section, the mean camber line and the
LE/TE edge circles of the nominal profile (the CAD's exact cut) and of the measured one (that
section's registered points), as FeaturePython objects in an "Airfoil" group beside the
section profiles. Each keeps its plane and links as inputs and rebuilds its shape when the
nominal's shape, the registration's points or the plane change (a signature is stored, so
opening a document is cheap); the numbers come from inspection.airfoil_stage.run_stage, the same
stage the `airfoil` and `report --airfoil` commands run.

No GUI imports: view providers come from the gui layer's hook (objects.set_view_provider_hook)."""

import dataclasses
import json

import numpy as np

import FreeCAD

from ..core import airfoil as kernel
from ..core import background
from ..core.contracts import json_default
from ..core.errors import InputError
from ..inspection import airfoil_stage as airfoil_mod
from . import objects
from .objects.base import (READ_ONLY, Proxy, add_property, add_table, building, finish,
                           shape_signature, signature)

GROUP_NAME = "Airfoil"
PROFILES = ("nominal", "measured")
MCL_SAMPLES = 200


def _definition(obj):
    """The object's airfoil definition, its ChordMethod property (the one a user edits)
    over the stored one; a document saved before objects kept a definition has only the
    chord method, the other fields then the stage's defaults."""
    text = getattr(obj, "Definition", "")
    stored = (kernel.AirfoilDefinition.from_dict(json.loads(text)) if text
              else airfoil_mod.DEFAULT_DEFINITION)
    return dataclasses.replace(stored, chord_method=obj.ChordMethod or "nose-tail")


def _vector(v):
    return FreeCAD.Vector(*[float(c) for c in np.asarray(v, dtype=float).ravel()[:3]])


class _SectionGeometry(Proxy):
    """What both kinds share: the section's plane and links, and the stage's result."""
    group = "Airfoil"

    def add_properties(self, obj):
        add, g = add_property, "Section"
        add(obj, "App::PropertyLink", "Nominal", g, "Nominal CAD the section is cut from")
        add(obj, "App::PropertyLink", "Registration", g,
            "Registration whose points give the measured profile")
        if "Profile" not in obj.PropertiesList:
            add(obj, "App::PropertyEnumeration", "Profile", g,
                "nominal: the CAD's exact cut; measured: the section's registered points")
            obj.Profile = list(PROFILES)
        add(obj, "App::PropertyString", "SectionLabel", g, "Section label (as in Table 2)",
            read_only=True)
        add(obj, "App::PropertyFloat", "HeightPct", g, "Section height, % of the span",
            read_only=True)
        add(obj, "App::PropertyVector", "PlaneOrigin", g, "A point of the section plane, mm")
        add(obj, "App::PropertyVector", "PlaneNormal", g, "Normal of the section plane")
        add(obj, "App::PropertyVector", "EngineAxis", g, "Engine axis (--engine-axis)")
        add(obj, "App::PropertyString", "ChordMethod", g,
            "Chord definition: nose-tail, caliper or tangent")
        add(obj, "App::PropertyString", "Definition", g,
            "The airfoil definition the profile was measured by (JSON)", hidden=True)
        add(obj, "App::PropertyIntegerList", "PointIndex", g,
            "Rows of the registration's points in this section", hidden=True)
        add(obj, "App::PropertyString", "InputSignature", g,
            "Signature of the inputs the shape was made from", hidden=True)
        self.add_results(obj)

    def add_results(self, obj):
        raise NotImplementedError

    def signature(self, obj):
        if obj.Nominal is None:
            return ""
        parts = [shape_signature(obj.Nominal.Shape), tuple(obj.PlaneOrigin),
                 tuple(obj.PlaneNormal), tuple(obj.EngineAxis), obj.ChordMethod, obj.Profile]
        if getattr(obj, "Definition", ""):
            parts.append(obj.Definition)
        if obj.Profile == "measured":
            if obj.Registration is None:
                return ""
            parts += [np.asarray(obj.Registration.PointsCad), list(obj.PointIndex)]
        return signature(*parts)

    def characteristics(self, obj):
        """(core.airfoil.Characteristics, PlaneFrame) of the object's profile, recomputed."""
        nominal = objects.nominal_of(obj.Nominal)
        result = None
        if obj.Profile == "measured":
            result = objects.registration_result(obj.Registration, nominal)
        plane = airfoil_mod.Plane(obj.SectionLabel, np.array(obj.PlaneOrigin, dtype=float),
                                  np.array(obj.PlaneNormal, dtype=float), obj.HeightPct,
                                  point_index=np.asarray(obj.PointIndex, dtype=int))
        opts = airfoil_mod.Options(engine_axis=tuple(obj.EngineAxis),
                                   definition=_definition(obj), draws=0)
        section = airfoil_mod.run_stage(nominal, [plane], opts, result).sections[0]
        ch = section.measured if obj.Profile == "measured" else section.nominal
        if ch is None:
            raise InputError("%s: section %s: %s" % (obj.Label, obj.SectionLabel,
                                                      "; ".join(section.notes)))
        return ch, section.frame

    def execute(self, obj):
        signature = self.signature(obj)
        if not signature:
            raise InputError("%s: no nominal (or, for a measured profile, no registration) "
                             "linked" % obj.Label)
        if signature == obj.InputSignature and not obj.Shape.isNull():
            return
        self.store(obj, *self.characteristics(obj))
        obj.InputSignature = signature


class CamberLine(_SectionGeometry):
    """The mean camber line: centres of the circles inscribed between the sides, extended to
    the LE and TE points (docs/user-guide.md), in the section plane (CAD frame)."""
    Type = "BladeInspect::CamberLine"

    def add_results(self, obj):
        ro = READ_ONLY
        add_table(obj, "Camber line", (
            ("App::PropertyFloat", "LengthMm", "Length of the camber line, LE to TE point, mm",
             ro),
            ("App::PropertyFloat", "ChordMm", "Chord by ChordMethod, mm", ro),
            ("App::PropertyFloat", "InletAngleDeg",
             "Inlet metal angle, from the engine axis, degrees", ro),
            ("App::PropertyFloat", "OutletAngleDeg",
             "Outlet metal angle, from the engine axis, degrees", ro),
            ("App::PropertyFloat", "MaxThicknessMm", "Largest inscribed circle's diameter, mm",
             ro),
            ("App::PropertyVector", "LePoint", "Leading-edge point, mm", ro),
            ("App::PropertyVector", "TePoint", "Trailing-edge point, mm", ro)))

    def store(self, obj, ch, frame):
        import Part
        xyz = frame.to_3d(ch.mcl.sample(MCL_SAMPLES))
        obj.Shape = Part.makePolygon([_vector(p) for p in xyz])
        obj.LengthMm = float(ch.mcl.length)
        # a value not measured (None: a sharp edge's metal angle, a sparse edge's chord): NaN,
        # as the table's "-"
        obj.ChordMm = np.nan if ch.chord_mm is None else float(ch.chord_mm)
        obj.InletAngleDeg = np.nan if ch.inlet_angle_deg is None else float(ch.inlet_angle_deg)
        obj.OutletAngleDeg = (np.nan if ch.outlet_angle_deg is None
                              else float(ch.outlet_angle_deg))
        obj.MaxThicknessMm = float(ch.max_thickness_mm)
        obj.LePoint = _vector(frame.to_3d(ch.le_point)[0])
        obj.TePoint = _vector(frame.to_3d(ch.te_point)[0])


class EdgeCircles(_SectionGeometry):
    """The circles fitted to the LE and TE zones (docs/user-guide.md), in the section plane."""
    Type = "BladeInspect::EdgeCircles"

    def add_results(self, obj):
        ro = READ_ONLY
        add_table(obj, "Edge circles", (
            ("App::PropertyFloat", "LeRadiusMm", "Leading-edge radius, mm", ro),
            ("App::PropertyFloat", "TeRadiusMm", "Trailing-edge radius, mm", ro),
            ("App::PropertyVector", "LeCenter", "Leading-edge circle's centre, mm", ro),
            ("App::PropertyVector", "TeCenter", "Trailing-edge circle's centre, mm", ro)))

    def store(self, obj, ch, frame):
        import Part
        normal = _vector(frame.normal)
        drawn = dict(ch.edge_circles())
        circles = []
        for name, radius_prop, centre_prop in (("LE", "LeRadiusMm", "LeCenter"),
                                               ("TE", "TeRadiusMm", "TeCenter")):
            if name not in drawn:
                # a withheld edge (a corner of the nominal): no circle, its radius NaN as the
                # table's "-", no centre to show
                setattr(obj, radius_prop, np.nan)
                setattr(obj, centre_prop, FreeCAD.Vector(np.nan, np.nan, np.nan))
                continue
            circle = drawn[name]
            centre = _vector(frame.to_3d(circle.center)[0])
            circles.append(Part.makeCircle(float(circle.radius), centre, normal))
            setattr(obj, radius_prop, float(circle.radius))
            setattr(obj, centre_prop, centre)
        obj.Shape = Part.Compound(circles)


KINDS = {"CamberLine": CamberLine, "EdgeCircles": EdgeCircles}


def _make(doc, cls, name, section, profile, ch, registration, nominal_obj, opts):
    obj = doc.addObject("Part::FeaturePython", name)
    cls(obj)
    obj.Nominal = nominal_obj
    obj.Registration = registration
    obj.Profile = profile
    plane = section.plane
    obj.SectionLabel = str(plane.label)
    obj.HeightPct = float(plane.height_pct)
    obj.PlaneOrigin = _vector(plane.origin)
    obj.PlaneNormal = _vector(plane.normal)
    obj.EngineAxis = _vector(opts.engine_axis)
    obj.ChordMethod = opts.definition.chord_method
    obj.Definition = json.dumps(opts.definition.as_dict(), sort_keys=True)
    obj.PointIndex = [int(i) for i in (plane.point_index if plane.point_index is not None
                                       else [])]
    obj.Label = "%s %s (%s)" % ({"CamberLine": "MCL", "EdgeCircles": "Edge circles"}[
        cls.__name__], plane.label, profile)
    cls.store(obj.Proxy, obj, ch, section.frame)
    finish(obj)
    return obj


def make_airfoil_objects(doc, stage, registration, opts, name=GROUP_NAME):
    """A group holding, per section of ``stage`` (inspection.airfoil_stage.Stage), a CamberLine and
    an EdgeCircles of the nominal profile and, where the section was measured, of the measured
    one; the stage's blocks (result.json's ``airfoil``) kept on the group for the table."""
    made = []
    with building(doc, "Airfoil"):
        group = doc.addObject("App::DocumentObjectGroup", name)
        group.addProperty("App::PropertyLink", "Registration", "Airfoil",
                          "Registration the characteristics were measured from")
        group.addProperty("App::PropertyString", "AirfoilJson", "Airfoil",
                          "Blocks of result.json's airfoil, lean_bow and settings")
        group.Registration = registration
        group.AirfoilJson = json.dumps(stage.extras(), default=json_default)
        # A record of the analysis, not an input: editing it would not re-measure.
        group.setEditorMode("Registration", ["ReadOnly"])
        group.setEditorMode("AirfoilJson", ["Hidden"])
        for section in stage.sections:
            for profile, ch in (("nominal", section.nominal), ("measured", section.measured)):
                if ch is None:
                    continue
                for kind, cls in KINDS.items():
                    background.tick()    # a GUI's event loop turns between the objects
                    if cls is EdgeCircles and not ch.edge_circles():
                        # both edges withheld: nothing to draw (an empty compound's void
                        # bounding box is an error line in the Report view)
                        continue
                    name = "%s_%s_%s" % (kind, section.plane.label, profile)
                    made.append(_make(doc, cls, name, section, profile, ch, registration,
                                      registration.Nominal, opts))
        group.Group = made
    return group


def analysis_of(group):
    """result.json's airfoil fields kept on an Airfoil group."""
    return json.loads(group.AirfoilJson or "{}")


def find_analysis(doc):
    """The newest Airfoil group of the document, else None."""
    for obj in reversed(doc.Objects):
        if "AirfoilJson" in obj.PropertiesList:
            return obj
    return None
