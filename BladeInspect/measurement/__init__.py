"""Measurement planning and execution on a rig: the section scan strategy (paper 3.1.1), paths
planned from the CAD, the complete raster, the rig calibration, and running a scan with its
pass journal and checkpoint."""
