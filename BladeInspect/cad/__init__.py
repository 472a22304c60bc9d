"""FreeCAD Part / OpenCASCADE geometry: loading CAD, faces as arrays, exact distances, lofting, demo blade."""

# FreeCAD's application must be initialised before Part is used as a library from a plain
# Python: without it, STEP export (and other OCC data exchange) crashes the interpreter.
import FreeCAD  # noqa: F401
