"""Identification of the torque -> slip -> Fx model from step-torque runs (paper Sec. 3).

Not built yet: this package will hold the sweeps on SingleWheel.fmu, the Eq. (15) fit and the
(W, tau) look-up tables (see ../shared/DESIGN.md, "Identified model").
"""
