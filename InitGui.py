# FreeCAD runs this file (executed, not imported: no __file__) when the GUI starts.
# Registration only: the commands are imported when the workbench is first activated.
import FreeCAD
import FreeCADGui


class BladeInspectWorkbench(FreeCADGui.Workbench):
    MenuText = FreeCAD.Qt.translate("Workbench", "BladeInspect")
    ToolTip = FreeCAD.Qt.translate(
        "Workbench", "Register optical scans of turbine blades to their CAD and map the "
        "deviations")

    def __init__(self):
        # The module folder is found through the package, since this file has no __file__.
        from BladeInspect.gui import resources
        self.__class__.Icon = resources.icon_path("BladeInspect")
        # FreeCAD loads BladeInspect_<its language>.qm from here, as for its own workbenches
        FreeCADGui.addLanguagePath(resources.TRANSLATIONS_DIR)
        FreeCADGui.updateLocale()

    def Initialize(self):
        from BladeInspect.core.blas_threads import limit_blas_threads
        from BladeInspect.gui import commands, loop_commands
        limit_blas_threads()
        self.appendToolbar("BladeInspect", commands.TOOLBAR)
        self.appendToolbar("BladeInspect loop", loop_commands.NAMES)
        self.appendMenu("BladeInspect", commands.MENU + ["Separator"] + loop_commands.NAMES)
        self.appendMenu("&Help", commands.HELP_MENU)
        commands.register_preferences()

    def Activated(self):
        pass

    def Deactivated(self):
        pass

    def GetClassName(self):
        return "Gui::PythonWorkbench"


FreeCADGui.addWorkbench(BladeInspectWorkbench())
