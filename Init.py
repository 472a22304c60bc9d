# FreeCAD runs this file (it is executed, not imported: no __file__) when it starts, GUI or not.
# Registration only; everything else lives in the BladeInspect package.
import FreeCAD

# FreeCAD's Test workbench and `freecadcmd -t` run the modules named here.
FreeCAD.__unit_test__ += ["TestBladeInspect"]
