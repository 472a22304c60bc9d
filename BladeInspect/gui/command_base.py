"""The base of the workbench's commands, as Fem's CommandManager: a command declares its name,
texts, icon, shortcut and when it is active as class attributes, and GetResources and IsActive
are read from them; a command class adds only what it does (Activated, or the task panel it
opens). Also the document look-ups the activity rules and the commands share."""
import FreeCAD
import FreeCADGui

from ..app import objects
from . import progress, resources
from .session import RIG


# ---------------------------------------------------------------- what the commands act on

def selected():
    return [s for s in FreeCADGui.Selection.getSelection()] if FreeCAD.GuiUp else []


def find_input(type_names):
    """The selected object of one of these BladeInspect types, else the newest in the active
    document, else None."""
    doc = FreeCAD.ActiveDocument
    if doc is None:
        return None
    for obj in selected():
        if objects.proxy_type(obj) in type_names:
            return obj
    for obj in reversed(doc.Objects):
        if objects.proxy_type(obj) in type_names:
            return obj
    return None


def find_nominal():
    """A nominal: a DemoBlade or CadModel object, else a selected Part feature with faces."""
    obj = find_input((objects.DemoBlade.Type, objects.CadModel.Type))
    if obj is not None:
        return obj
    for sel in selected():
        shape = getattr(sel, "Shape", None)
        if shape is not None and not shape.isNull() and shape.Faces:
            return sel
    return None


def inputs_of(doc, type_names):
    """The document's BladeInspect objects of these types, oldest first."""
    if doc is None:
        return []
    return [obj for obj in doc.Objects if objects.proxy_type(obj) in type_names]


def nominals_of(doc):
    """What can serve as the nominal: the DemoBlade and CadModel objects, and a selected Part
    feature with faces (find_nominal's)."""
    found = inputs_of(doc, (objects.DemoBlade.Type, objects.CadModel.Type))
    chosen = find_nominal()
    if chosen is not None and chosen not in found:
        found.append(chosen)
    return found


def find_measurement():
    return find_input((objects.Measurement.Type,))


def find_registration():
    return find_input((objects.Registration.Type,))


# ---------------------------------------------------------------- when a command is active

def _registration_with(*links):
    reg = find_registration()
    return reg is not None and all(getattr(reg, link) is not None for link in links)


# Command.is_active names one of these (besides: no job running).
IS_ACTIVE = {
    "always": lambda: True,
    "with_rig": lambda: RIG.connected,
    "with_nominal": lambda: find_nominal() is not None,
    "with_measurement": lambda: find_measurement() is not None,
    "with_measurement_and_nominal": lambda: (find_measurement() is not None
                                             and find_nominal() is not None),
    "with_registration": lambda: find_registration() is not None,
    "with_registered_nominal": lambda: _registration_with("Nominal"),
    "with_registered_inputs": lambda: _registration_with("Measurement", "Nominal"),
}


class Command:
    """A BladeInspect_<Verb> command. ``name``: its FreeCAD name (also its icon's, unless
    ``pixmap`` names another); ``menu``, ``tip``: its texts, marked QT_TRANSLATE_NOOP with the
    name as context; ``accel``: its shortcut (none by default); ``is_active``: a key of
    IS_ACTIVE; ``panel``: a task panel class that Activated shows as panel(self.start)."""
    name = ""
    menu = ""
    tip = ""
    pixmap = None
    accel = ""
    is_active = "always"
    panel = None

    def GetResources(self):
        found = {"Pixmap": resources.icon_path(self.pixmap or self.name), "MenuText": self.menu,
                 "ToolTip": self.tip}
        if self.accel:
            found["Accel"] = self.accel
        return found

    def IsActive(self):
        return not progress.busy() and IS_ACTIVE[self.is_active]()

    def Activated(self):
        FreeCADGui.Control.showDialog(self.panel(self.start))
