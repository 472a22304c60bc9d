"""The rig as hardware: the sensor model, four-axis kinematics, the simulated rig and the serial
drivers with their protocols. What to measure and how (scan strategy, planning, calibration)
lives in measurement/."""
