"""BladeInspect: automated registration and inspection of turbine blade scans against CAD.

Layers, imports pointing down only:
    core     numpy/scipy numerics, never imports FreeCAD
    cad      FreeCAD Part / OpenCASCADE geometry
    rig      sensor model, four-axis kinematics, simulated and serial rigs, scan strategy
    inspect  the pipeline stages, sections, reports, batches
    app      FeaturePython document objects (no GUI imports)
    gui      commands, task panels, view providers (FreeCADGui / PySide only here)
"""

__version__ = "0.1.0"
NAME = "BladeInspect"
