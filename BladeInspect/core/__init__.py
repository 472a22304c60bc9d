"""Numerics with numpy/scipy only. Nothing in this package may import FreeCAD, Part or Qt."""
