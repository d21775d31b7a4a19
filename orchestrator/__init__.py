"""The co-simulation engine (``rover_cosim.orchestrator``): FMUs and Python blocks coupled at a
fixed communication step.

- ``system``: system files (TOML) parsed and checked, one function per section;
- ``blocks``: Python blocks (sources; the protocol user blocks follow);
- ``participants``: the participant protocol and its two kinds, FMU (FMPy's FMI 2.0 slave) and
  Python block;
- ``wiring``: slots of the value vector, which participant reads what;
- ``master``: the master algorithms (Jacobi, Gauss-Seidel), one class each, and ``run``;
- ``recorder``: recorded values in a preallocated array;
- ``runs``: a run written to disk (CSV + JSON sidecar, both or neither);
- ``libcosim``: the same system run by libcosimpy, for cross-checks and benchmarks;
- ``examples``: the shipped example systems.

The engine imports ``rover_cosim.common`` only: no identification, no control, no FMU build.
"""
