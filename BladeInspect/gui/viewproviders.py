"""View providers of BladeInspect's document objects: icons, display modes, the deviation legend
and the task panels opened by double-click. They show what the objects hold and compute nothing.
Importing this module registers them with the app layer's objects."""
import FreeCAD
import FreeCADGui

from ..app import airfoil_objects, objects
from ..app.objects.base import Stateless
from . import legend, resources
from .taskpanels import AirfoilPanel, RegistrationPanel, show_panel


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
    icon = "BladeInspect_DeviationMap"

    def attach(self, vobj):
        super().attach(vobj)
        self.legend = None
        self.show_legend(vobj)

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
                                             [c[:3] for c in obj.LegendColors])
            root.addChild(self.legend)

    def updateData(self, obj, prop):
        if prop in ("LegendValues", "LegendColors"):
            self.show_legend(obj.ViewObject)

    def onChanged(self, vobj, prop):
        if prop == "Visibility" and hasattr(self, "legend"):
            self.show_legend(vobj)


class ViewProviderAirfoilGeometry(ViewProvider):
    """A camber line or edge circles: nominal in dark orange/green, measured lighter and
    dashed-looking thin; double-click shows the characteristics table of its analysis."""
    colours = {"nominal": (0.85, 0.33, 0.0), "measured": (1.0, 0.65, 0.2)}

    def configure(self, vobj):
        vobj.LineColor = self.colours.get(vobj.Object.Profile, (0.85, 0.33, 0.0))
        vobj.LineWidth = 3 if vobj.Object.Profile == "nominal" else 2

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
    colours = {"nominal": (0.1, 0.6, 0.2), "measured": (0.45, 0.85, 0.45)}


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
