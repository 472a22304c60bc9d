"""BladeInspect: automated registration and inspection of turbine blade scans against CAD.

Layers, imports pointing down only:
    core         numpy/scipy numerics, never imports FreeCAD
    cad          FreeCAD Part / OpenCASCADE geometry
    rig          the hardware: sensor model, four-axis kinematics, simulated and serial rigs
    measurement  what to measure and how: scan strategy, planned paths, calibration, scans
    inspection   the pipeline stages, sections, reports, batches
    app          FeaturePython document objects (no GUI imports)
    gui          commands, task panels, view providers (FreeCADGui / PySide only here)
"""

__version__ = "0.1.0"
NAME = "BladeInspect"
