"""View providers of BladeInspect's document objects: icons, display modes, the deviation legend
and the task panels opened by double-click. They show what the objects hold and compute nothing.
Importing this module registers them with the app layer's objects."""
import FreeCAD
import FreeCADGui
import numpy as np
from pivy import coin

from ..app import airfoil_objects, objects
from ..app.objects.deviation_map import tolerance_of
from ..core import colourmap
from ..app.objects.base import Stateless
from . import legend, resources
from .i18n import translate
from .taskpanels import AirfoilPanel, RegistrationPanel, show_panel

# The out-of-tolerance points are drawn again this much larger than the map's points.
OUT_OF_TOLERANCE_SCALE = 2.0


class ViewProvider(Stateless):
    """Nothing of the view provider is saved: it is made again from the object's type."""
    icon = "BladeInspect"

    def __init__(self, vobj):
        vobj.Proxy = self

    def attach(self, vobj):
        self.Object = vobj.Object

    def configure(self, vobj):
        """Display defaults for an object just made (not applied to restored ones' choices)."""

    def getIcon(self):
        return resources.icon_path(self.icon)


class ViewProviderNominal(ViewProvider):
    icon = "BladeInspect_DemoBlade"

    def configure(self, vobj):
        vobj.Transparency = 40


class ViewProviderCadModel(ViewProviderNominal):
    icon = "BladeInspect_LoadCad"


class ViewProviderMeasurement(ViewProvider):
    icon = "BladeInspect_ImportPoints"

    def configure(self, vobj):
        vobj.PointSize = 2
        vobj.ShapeColor = (0.1, 0.1, 0.4)


class ViewProviderReconstruction(ViewProvider):
    icon = "BladeInspect_Reconstruct"

    def configure(self, vobj):
        vobj.LineColor = (0.9, 0.45, 0.1)
        vobj.LineWidth = 2
        vobj.ShapeColor = (0.95, 0.7, 0.4)
        vobj.Transparency = 50


class ViewProviderRegistration(ViewProvider):
    icon = "BladeInspect_Register"

    def setEdit(self, vobj, mode=0):
        if mode != 0:
            return None
        FreeCADGui.Control.showDialog(RegistrationPanel(vobj.Object))
        return True

    def unsetEdit(self, vobj, mode=0):
        FreeCADGui.Control.closeDialog()
        return True

    def doubleClicked(self, vobj):
        FreeCADGui.ActiveDocument.setEdit(vobj.Object.Name)
        return True


class ViewProviderDeviationMap(ViewProvider):
    """The coloured points with the legend; the points beyond the tolerance drawn once more,
    larger, in their class colours and in front of everything, so the worst points are seen
    among many."""
    icon = "BladeInspect_DeviationMap"

    def attach(self, vobj):
        super().attach(vobj)
        self.legend = None
        self.outliers = None
        self.show_legend(vobj)
        self.show_outliers(vobj)

    def configure(self, vobj):
        vobj.DisplayMode = "Color"
        vobj.PointSize = 4

    def show_legend(self, vobj):
        root = vobj.RootNode
        if self.legend is not None:
            root.removeChild(self.legend)
            self.legend = None
        obj = vobj.Object
        if len(obj.LegendValues) >= 2 and vobj.Visibility:
            self.legend = legend.legend_node(list(obj.LegendValues),
                                             [c[:3] for c in obj.LegendColors],
                                             **self.class_swatches(obj))

            root.addChild(self.legend)

    @staticmethod
    def class_swatches(obj):
        """The legend's out-of-tolerance entries with their counts (none for a map made
        before the classes were)."""
        counts = list(getattr(obj, "OutOfTolerance", []))
        if len(counts) != 2:
            return {}
        tolerance = tolerance_of(obj)
        return {"above": (translate("BladeInspect", "> %+.3f: %d points")
                          % (tolerance, counts[1]), colourmap.ABOVE_COLOUR),
                "below": (translate("BladeInspect", "< %+.3f: %d points")
                          % (-tolerance, counts[0]), colourmap.BELOW_COLOUR)}

    def show_outliers(self, vobj):
        """A separator of its own under the root: the out-of-tolerance points, larger."""
        root = vobj.RootNode
        if self.outliers is not None:
            root.removeChild(self.outliers)
            self.outliers = None
        obj = vobj.Object
        if "Tolerance" not in obj.PropertiesList or not len(obj.Deviation) or obj.Limit <= 0:
            return
        deviation = np.asarray(obj.Deviation, dtype=float)
        classes = colourmap.deviation_classes(deviation, tolerance_of(obj))
        index = np.flatnonzero(classes != colourmap.WITHIN)
        points = obj.Points.Points
        if not len(index) or len(points) != len(deviation):
            return
        node = coin.SoSeparator()
        light = coin.SoLightModel()
        light.model = coin.SoLightModel.BASE_COLOR
        node.addChild(light)
        style = coin.SoDrawStyle()
        style.style = coin.SoDrawStyle.POINTS
        style.pointSize = OUT_OF_TOLERANCE_SCALE * max(vobj.PointSize, 2.0)
        node.addChild(style)
        if hasattr(coin, "SoDepthBuffer"):
            # In front of everything, as inspection packages flag the worst points: the map's
            # neighbouring points, nearer by a hair, would otherwise cover their middles.
            depth = coin.SoDepthBuffer()
            depth.test = False
            node.addChild(depth)
        material = coin.SoMaterial()
        colours = [colourmap.ABOVE_COLOUR if classes[i] == colourmap.ABOVE
                   else colourmap.BELOW_COLOUR for i in index]
        material.diffuseColor.setValues(0, len(colours), colours)
        node.addChild(material)
        binding = coin.SoMaterialBinding()
        binding.value = coin.SoMaterialBinding.PER_VERTEX
        node.addChild(binding)
        coords = coin.SoCoordinate3()
        coords.point.setValues(0, len(index), [tuple(points[i]) for i in index])
        node.addChild(coords)
        node.addChild(coin.SoPointSet())
        self.outliers = node
        if vobj.Visibility:
            root.addChild(node)

    def updateData(self, obj, prop):
        if prop in ("LegendValues", "LegendColors", "OutOfTolerance"):
            self.show_legend(obj.ViewObject)
        if prop in ("Deviation", "Tolerance", "Points"):
            self.show_outliers(obj.ViewObject)

    def onChanged(self, vobj, prop):
        if prop == "Visibility" and hasattr(self, "legend"):
            self.show_legend(vobj)
            self.show_outliers(vobj)
        if prop == "PointSize" and hasattr(self, "outliers"):
            self.show_outliers(vobj)


class ViewProviderAirfoilGeometry(ViewProvider):
    """A camber line or edge circles: neutral greys and thin, the measured one dashed, so over
    the deviation map they read as construction lines rather than as deviations; double-click
    shows the characteristics table of its analysis."""
    colours = {"nominal": (0.25, 0.25, 0.25), "measured": (0.45, 0.45, 0.45)}

    def configure(self, vobj):
        measured = vobj.Object.Profile == "measured"
        vobj.LineColor = self.colours["measured" if measured else "nominal"]
        vobj.LineWidth = 1
        if measured:
            vobj.DrawStyle = "Dashed"

    def doubleClicked(self, vobj):
        groups = [o for o in vobj.Object.InList if "AirfoilJson" in o.PropertiesList]
        if not groups:
            return False
        show_panel(AirfoilPanel(airfoil_objects.analysis_of(groups[0])))
        return True


class ViewProviderCamberLine(ViewProviderAirfoilGeometry):
    icon = "BladeInspect_CamberLine"


class ViewProviderEdgeCircles(ViewProviderAirfoilGeometry):
    icon = "BladeInspect_EdgeCircles"


VIEW_PROVIDERS = {
    airfoil_objects.CamberLine.Type: ViewProviderCamberLine,
    airfoil_objects.EdgeCircles.Type: ViewProviderEdgeCircles,
    objects.DemoBlade.Type: ViewProviderNominal,
    objects.CadModel.Type: ViewProviderCadModel,
    objects.Measurement.Type: ViewProviderMeasurement,
    objects.Reconstruction.Type: ViewProviderReconstruction,
    objects.Registration.Type: ViewProviderRegistration,
    objects.DeviationMap.Type: ViewProviderDeviationMap,
}


def attach_view_provider(obj):
    """Give a BladeInspect object its view provider (new objects, and documents saved without a
    GUI, whose objects have none)."""
    cls = VIEW_PROVIDERS.get(objects.proxy_type(obj))
    vobj = obj.ViewObject
    if cls is None or vobj is None or isinstance(getattr(vobj, "Proxy", None), cls):
        return
    cls(vobj)
    try:
        cls.configure(vobj.Proxy, vobj)
    except Exception as exc:  # a display default that does not apply is not worth failing for
        FreeCAD.Console.PrintLog("BladeInspect: %s: %s\n" % (obj.Name, exc))


objects.set_view_provider_hook(attach_view_provider)
