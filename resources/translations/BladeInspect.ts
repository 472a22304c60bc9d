<?xml version="1.0" encoding="utf-8"?>
<!DOCTYPE TS>
<TS version="2.1">
<context>
    <name>BladeInspect</name>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>% chord</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>%d isolated points treated as sensor outliers.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>%d sections and the out-of-tolerance spots judged against ±%.3f mm (%s).</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>%s (not measured)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>%s. Pose uncertainty %.2f µm after the planned scan (%.2f µm after the blind scan); ICP weights: %s. Files in %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/progress.py"/>
        <source>%s: cancelled</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/progress.py"/>
        <source>%s: done</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>*: the worst deviation is + under one objective and - under another; the change is of its size, which the verdict judges</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>1: one side; 2: the part turned over to scan the other</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>2 turns the part over to scan the other side</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/viewproviders.py"/>
        <source>&lt; %+.3f: %d points</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/viewproviders.py"/>
        <source>&gt; %+.3f: %d points</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>A letter (x, y, z, -x, ...) or a vector</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>A parameter of the parametric demo blade, interpolated from hub to tip</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>A section is rescanned until every point lies within ε of the sensor's standoff</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Accuracy</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Actual</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Add CMM file</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Against the simulator's truth: axis position %.2f um, direction %.5f deg.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Airfoil analysis</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Airfoil characteristics</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Airfoil characteristics of %d sections; a value not measured is shown without a verdict, with its reason.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Airfoil characteristics...</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Airfoil: FAIL, %d of %d characteristics: %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Airfoil: NOT PROVEN, %d of %d characteristics: %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Airfoil: PASS (%d characteristics)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Airfoil: no characteristic toleranced</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Allow mismatch</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Angle of the chord named (its method) from the engine axis in the section plane, LE towards TE</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Area enclosed by the profile</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Axial chord</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Axis offset (simulated)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Axis tilt (simulated)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>BladeInspect</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <location filename="../../BladeInspect/gui/progress.py"/>
        <source>BladeInspect: %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/progress.py"/>
        <source>BladeInspect: %s cancelled</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>BladeInspect: %s uses %s (%s)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>BladeInspect: report in %s; ICP weights: %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>BladeInspect: rig connected (%s)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/forms.py"/>
        <source>Browse...</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>CAD files (*.step *.stp *.iges *.igs *.brep *.brp *.FCStd *.dat);;All files (*)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>CMM
%</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>CMM LE
mm</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>CMM RMS</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>CMM TE
mm</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>CMM file</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>CMM files (*.csv *.txt *.dat);;All files (*)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>CMM max</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>CMM points</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>CMM points in the section</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>CMM: %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>CSV: characteristic,section,lower,upper[,nominal]; empty: every characteristic reported, none judged</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Calibrate</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Calibrate rig</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Camber / chord at the hub</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Camber / chord at the tip</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Camber line's tangent at the LE, from the engine axis</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Camber line's tangent at the TE, from the engine axis</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/progress.py"/>
        <source>Cancel</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Centroid %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Centroid of the section area, in the CAD frame</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Change</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Characteristic</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Characteristics (*.csv);;All files (*)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/forms.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Characteristics file</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/forms.py"/>
        <source>Choose the file</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/forms.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Chord</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Chord (%s)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Chord at the hub</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Chord at the tip</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Chord by the method named (nose-tail: LE point to TE point; caliper; tangent)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Chord, stagger, thickness, edge radii, angles, shift and twist per section, judged in the verdict (the inspect command's default; off: --no-airfoil)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Chord: %s; U = 2 x the %s (%s).</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Colour map limit</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Connect rig</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Continue the inspection that was cancelled or failed, with its options, from what it measured (kept in %s); unchecked: a new inspection replaces it</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/forms.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Decision rule</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Demo blade</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Dev.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/legend.py"/>
        <source>Deviation [mm]</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Deviation from the nominal under each fit objective; the colour is its verdict (green pass, amber not proven, red fail, none: not judged), the verdict and U in the tooltip.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Deviation map</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Deviation: actual - nominal</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Diameter of the largest inscribed circle</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Displacement of the measured section against the nominal in its plane (x along the engine axis)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Distance between points along a section</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Distance between sections; 0 spreads them over the span</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Distance from the sensor to the middle of its working range</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/forms.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Engine axis</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Expanded uncertainty U (k = 2) of the worst deviation, mm</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Expanded uncertainty U (k = 2): the decision's, else 2 u of the stated standard uncertainty</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Extent of the profile along the engine axis</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>FAIL</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Fit</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Fit sensitivity</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Fixture pose of the simulated rig and the registration's sampling</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Form and location error</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Form error</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/forms.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Free DOF</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Free degrees of freedom, any of tx,ty,tz,rx,ry,rz and t_stacking,r_stacking,t_engine,r_engine; empty: all six</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Half the depth of the sensor's working range: it measures from zₛ − δ to zₛ + δ</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>How the chord line is drawn</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/forms.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>ICP weights</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Import points</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Inlet metal angle</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Inspect</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Inspection: Table 2 at the nominal sections</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Keep the registration, with a warning, when too few points lie near the CAD's surface (another part's scan, or a part far out of tolerance); off: refuse it</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>LE max
mm</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>LE radius</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>LE radius at the hub</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>LE radius at the tip</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>LE thickness at %s mm</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Largest absolute deviation at the leading edge (mm)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Largest absolute deviation at the trailing edge (mm)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Largest absolute deviation from the CAD in the section (mm)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Largest change: %s, %.4f mm; the verdict %s with the fit.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Largest contour deviation after the section's own 2D best fit</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Largest contour deviation before the section's 2D fit</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Largest minus smallest over the objectives: of a worst deviation's size |value| (what the verdict judges against ±T), of an airfoil characteristic's value</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Lean and bow: largest bow at section %s.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Lean of the tip (+Y)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Least-squares region weights, e.g. LE=2,TE=2,suction=1,pressure=1</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Load CAD</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Max |dev|
mm</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Max. thickness</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Max. thickness position</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Measured points</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Measurement error</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Most cambered point / chord</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>NOT JUDGED</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>NOT PROVEN</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Name the serial port</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>No measured points in the document</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>No nominal CAD in the document</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>No registration in the document</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Nominal</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Nominal CAD</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Nominal sections to measure, % of the span from hub to tip</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/forms.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Objective</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Outlet metal angle</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Outlier fraction</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>PASS</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Part</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Part verdict</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Point files (*.csv *.xyz *.asc *.txt *.ply *.pcd);;All files (*)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Point spacing</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Points</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Points per side and section</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Points the sensor measures per second (the scan time estimate)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Port</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Pose error %.3f um = %.2f x its bound (%.3f um). Residual RMS %.4f mm (injected %.4f), min %.4f, max %.4f mm; paper: RMS 0.0019, min -0.0053, max 0.006.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Profile tolerance</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>RIG.json from Calibrate; empty: the nominal kinematics</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>RMS
mm</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>RMS of the CMM's deviations (mm)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>RMS of the deviations in the section (mm)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Radius of the circle fitted to the leading-edge zone</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Radius of the circle fitted to the trailing-edge zone</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Random seed</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Random seed of the coarse stage</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Random seed of the simulated rig's fixture pose and noise</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Random seed of the simulated rig's noise</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Rate</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Reconstruct</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Register</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Registered points in the section's band</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Registration</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Registration: %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Report</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Report folder</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Rescan a section until every point is within this distance of the sensor's standoff</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Rescan criterion ε</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Resume the interrupted inspection</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Resumed from the interrupted inspection's checkpoint.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Rig</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/forms.py"/>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Rig calibration</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Rig calibration (*.json);;All files (*)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Rig: %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Rotary axis through (%.4f, %.4f, %.4f) mm, direction (%.7f, %.7f, %.7f).</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Rotation of the measured section against the nominal (its 2D best fit)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Scan</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Scan strategy</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Section</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Section
% span</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Section %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Section analysis</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Section area</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Section height, % of the span from hub to tip</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/forms.py"/>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Section heights</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Section heights (%)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Section label</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Section spacing</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Sections</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Sections lofted</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Sections per scan</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Sections scanned over the span</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Sections the Scan command measures over the span</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Seed</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Seed (simulated)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Seed of the simulated rig and of the registration's sampling: the same seed repeats a run</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Sensor</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Serial port</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Share of the CMM's points within the band</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Share of the section's points within ±%s mm of the CAD</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Shift %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Sides</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Sides scanned</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Simulated rig</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Simulation</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Simulation test bed</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Span</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Span
%</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Sphere diameter</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Stagger angle (%s)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Stagger at the hub</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Standoff criterion ε</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Standoff zₛ</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/progress.py"/>
        <source>Stop %s; the document keeps what it had before</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Surface points</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Sweep of the tip (+X)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>TE max
mm</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>TE radius</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>TE radius at the hub</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>TE radius at the tip</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>TE thickness at %s mm</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>TUR</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Table 2: optical and CMM</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Test uncertainty ratio: tolerance / U</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>The CAD the points are registered to (the selected one when a CAD is selected)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>The CAD the rig's part is inspected against (the selected one when a CAD is selected)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>The CAD's value (or the characteristics file's)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>The CMM's largest absolute deviation (mm)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>The CMM's largest absolute deviation at the leading edge (mm)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>The CMM's largest absolute deviation at the trailing edge (mm)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>The characteristic; its field name in airfoil.json, airfoil.csv and the --characteristics file in the tooltip</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>The deviation at which the colour map saturates; 0: the profile tolerance</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>The fine ICP's weights: snr, the paper's SNR-linear weights; sensor, the sensor model's 1/(sigma_beam cos incidence)^2 (needs the readings' angle_deg); default: sensor when the points carry snr and angle_deg, else snr</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>The folder is temporary: a new inspection begun instead, or closing FreeCAD, deletes it.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>The measured value</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>The part's verdict under the %s fit (%s); the table below gives it under every fit.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>The point set to register (the selected one when a point set is selected)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>The profile tolerance each section is judged against</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>The profile tolerance each section is judged against (±, mm)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>The registered measurement to analyse (the selected one when a registration is selected)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>The rig's serial port</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>The section by its nominal height, % of the span from hub to tip</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>The section's worst deviation judged against the tolerance with its U: pass, not proven, fail</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>The sensor's stated accuracy, added to the tolerance when a scan is checked against the CAD</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>The simulated rig measures the nominal CAD; a serial port drives the real rig</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Thickest point / chord</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Thickness / chord at the hub</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Thickness / chord at the tip</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Thickness normal to the camber line at this distance from the LE point</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Thickness normal to the camber line at this distance from the TE point</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Tilt from +Y: %.4f deg about Z, %.4f deg about X. Sphere measured %.4f mm (nominal %.4f); circle residual RMS %.4f mm.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Tol.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Tolerance</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Tolerance and colour map</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Tolerance on the deviation (lower / upper limit)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Twist</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Twist exponent</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Twist, hub to tip</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Unit</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Unit of the nominal, actual, deviation, U and tolerance</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Value under this fit objective; the cell's colour is its verdict (tooltip)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>Verdict</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>What was measured is kept in %s. Run Inspect again with 'Resume the interrupted inspection' checked to continue from there.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Where the largest inscribed circle lies, % of the chord from the LE</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Within
±%s mm
%%</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>Working range ±δ</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>Worst deviation</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Write the rig calibration</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Written to %s.</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/forms.py"/>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>Zone weights</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>all six</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>changes</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>does not change</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>fail</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/progress.py"/>
        <source>internal error: %s: %s (details in the report view's log)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>iso14253: pass / not proven / fail (ISO 14253-1); simple: simple acceptance</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>least-squares: the robust ICP's pose; minimax: minimum zone; tolerance: largest margin inside the tolerance; datum: the CAD's datum faces</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>no interrupted inspection of %s to resume</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/taskpanels.py"/>
        <source>none</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>not judged</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>not measured</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>not proven</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>opening %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>pass</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>pass, not proven, fail (the decision rule with U), not judged without a tolerance</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/preferences.py"/>
        <source>points/s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>reading %s</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>reading %s and cutting the sections</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>simulated (none connected)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>simulated rig: load a CAD or build the demo blade first</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/progress.py"/>
        <source>starting</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/forms.py"/>
        <source>the Register panel's 'Allow mismatch' box</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/inspection/characteristic_names.py"/>
        <source>x (engine axis)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>±U
k=2</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/tables.py"/>
        <source>±U
mm</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_AddCmm</name>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Add CMM file...</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Compare a CMM file's sections with the optical ones (Table 2): for an inspection, at its nominal sections</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_Airfoil</name>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Airfoil analysis...</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Airfoil characteristics per section (chord, stagger, thickness, edge radii, angles, shift, twist) nominal and measured, judged against a characteristics file; the mean camber lines and edge circles added to the document</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_Calibrate</name>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Calibrate rig...</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Measure a reference sphere at several rotary angles, find the rotary axis and write RIG.json (simulated rig or a serial port)</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_ConnectRig</name>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Connect rig...</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Connect the four-axis rig: the simulated rig (needs a nominal) or a serial port</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_DemoBlade</name>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Build the parametric demo blade as the nominal CAD (parameters in a task panel)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Demo blade</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_DeviationMap</name>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Colour the registered points by signed deviation (limits from the preferences)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Deviation map</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_Help</name>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>BladeInspect user guide</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Open the user guide: the workflows, their panels and what the results mean</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_ImportPoints</name>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Import a measured point cloud (csv/xyz/asc/txt with optional SNR, ply, pcd)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Import points...</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_Inspect</name>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Inspect...</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>The whole loop: blind section scan, registration, paths planned from the CAD at its nominal sections (drawn before they run), their scan, Table 2 and verdict</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_LoadCad</name>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Load CAD...</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Load the nominal blade from a STEP, IGES, BREP or FCStd file (or a section table)</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_Preferences</name>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Preferences...</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Sensor and rig parameters, tolerance and colour limits</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_Reconstruct</name>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Fit cubic B-spline section curves to the measurement and loft them into surfaces</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Reconstruct</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_Register</name>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Register</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Register the measurement to the nominal with no starting pose (PCA, then SNR-weighted ICP), move it to the chosen fit and show the pose with its uncertainty and the fit-sensitivity table</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_Report</name>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Report...</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Write the inspection report (HTML and PDF, result.json, deviations.csv) to a folder</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_Scan</name>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Scan the blade section by section with the connected rig (progress and abort)</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Scan...</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_SectionAnalysis</name>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Profile errors per section (Table 2): RMS, worst deviation, leading/trailing edge</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/commands.py"/>
        <source>Section analysis</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>BladeInspect_Simulate</name>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>Simulation test bed...</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../BladeInspect/gui/loop_commands.py"/>
        <source>The paper's simulation test bed: points from the CAD (or the demo blade) at a random pose with measurement error, registered blind; pose error against its bound</source>
        <translation type="unfinished"></translation>
    </message>
</context>
<context>
    <name>Workbench</name>
    <message>
        <location filename="../../InitGui.py"/>
        <source>BladeInspect</source>
        <translation type="unfinished"></translation>
    </message>
    <message>
        <location filename="../../InitGui.py"/>
        <source>Register optical scans of turbine blades to their CAD and map the deviations</source>
        <translation type="unfinished"></translation>
    </message>
</context>
</TS>
