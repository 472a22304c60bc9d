"""FreeCAD Part / OpenCASCADE geometry: loading CAD, faces as arrays, exact distances, lofting, demo blade."""
