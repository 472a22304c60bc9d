"""Everything GUI: commands, task panels, view providers. Imported only when FreeCAD.GuiUp."""
