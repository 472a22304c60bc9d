"""Measurement side: sensor model, four-axis kinematics, simulated rig, serial drivers, scan strategy."""
