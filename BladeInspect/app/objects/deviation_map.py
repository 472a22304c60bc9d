"""DeviationMap: the registered points coloured by deviation, with a legend, as a document
object."""

from ...core import colourmap
from ...core.errors import InputError
from .base import Proxy, add_property, attach_view, building, points_kernel, proxy_type
from .registration import Registration, make_registration, registration_points


class DeviationMap(Proxy):
    """The registered points coloured by signed deviation (saturating at +-Limit), those beyond
    +-Tolerance in the out-of-tolerance colours (core.colourmap), shown per point through the
    `Color` list, with the legend's values and colours and the out-of-tolerance counts for the
    view."""
    Type = "BladeInspect::DeviationMap"

    def add_properties(self, obj):
        add = add_property
        g = "Deviation map"
        add(obj, "App::PropertyLink", "Registration", g, "Registration whose deviations are shown")
        add(obj, "App::PropertyFloat", "Limit", g,
            "Deviation at which the colours saturate (blue -Limit, green 0, red +Limit), mm")
        add(obj, "App::PropertyColorList", "Color", g, "Colour of every point", hidden=True)
        add(obj, "App::PropertyFloatList", "Deviation", g, "Signed deviation of every point, mm",
            hidden=True)
        add(obj, "App::PropertyFloatList", "LegendValues", g, "Legend tick values, mm",
            read_only=True)
        add(obj, "App::PropertyColorList", "LegendColors", g, "Colour at each legend tick",
            hidden=True)
        add(obj, "App::PropertyInteger", "NPoints", g, "Points shown", read_only=True)
        add(obj, "App::PropertyFloat", "Tolerance", g,
            "Points beyond +-Tolerance get the out-of-tolerance colours (magenta above, "
            "near-black below), mm; 0: Limit")
        add(obj, "App::PropertyIntegerList", "OutOfTolerance", g,
            "Points below -Tolerance and above +Tolerance", read_only=True)

    def execute(self, obj):
        if obj.Registration is None:
            raise InputError("%s: no registration linked" % obj.Label)
        if obj.Limit <= 0:
            raise InputError("%s: Limit must be positive, got %g" % (obj.Label, obj.Limit))
        if obj.Tolerance < 0:
            raise InputError("%s: Tolerance must not be negative, got %g"
                             % (obj.Label, obj.Tolerance))
        tolerance = tolerance_of(obj)
        points, deviation, _ = registration_points(obj.Registration)
        obj.Points = points_kernel(points)
        obj.Deviation = deviation.tolist()
        obj.Color = [tuple(c) for c in
                     colourmap.classed_colours(deviation, tolerance, obj.Limit).tolist()]
        obj.OutOfTolerance = list(colourmap.class_counts(deviation, tolerance))
        values, colours = colourmap.legend_ticks(obj.Limit)
        obj.LegendValues = values.tolist()
        obj.LegendColors = [tuple(c) for c in colours.tolist()]
        obj.NPoints = len(deviation)


def tolerance_of(obj):
    """The deviation beyond which a DeviationMap's points are out of tolerance, mm."""
    return obj.Tolerance if obj.Tolerance > 0 else obj.Limit


def make_deviation_map(doc, registration, limit, name="DeviationMap", tolerance=None):
    """A DeviationMap of `registration`: a Registration document object, or a
    RegistrationResult (a Registration object holding it is made first); ``tolerance``
    (default ``limit``) marks the out-of-tolerance points."""
    with building(doc, "Deviation map"):
        if proxy_type(registration) != Registration.Type:
            registration = make_registration(doc, registration)
        obj = doc.addObject("Points::FeaturePython", name)
        DeviationMap(obj)
        obj.Registration = registration
        obj.Limit = float(limit)
        obj.Tolerance = float(tolerance) if tolerance is not None else 0.0
        obj.Proxy.execute(obj)
        obj.purgeTouched()
        attach_view(obj)
    return obj
