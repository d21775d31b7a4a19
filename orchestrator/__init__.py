"""The co-simulation engine (``rover_cosim.orchestrator``): FMUs and Python blocks coupled at a
fixed communication step, in libcosim's shape.

The system model (data):
- ``model``: the typed system: FMU and block components with their parameter and start values,
  connections, recorded ports, simulation settings;
- ``builder``: :class:`SystemBuilder`, a system built in code and checked call by call
  (``replace_settings``, ``with_parameters``: changed copies of a system);
- ``system``: system files (TOML), a reader and a writer of the model; ``ssp``: SSP 1.0
  archives, the same; ``examples``: the shipped system files; ``loops``: algebraic loops.

Running it:
- ``blocks``: Python blocks (sources; the protocol user blocks follow);
- ``participants``: the participant protocol and its two kinds, FMU (FMPy's FMI 2.0 and 3.0 Co-Simulation
  and Model Exchange instances) and
  Python block; ``unpacking``: each run's temporary folder of unpacked FMUs;
- ``wiring``: slots of the value vector, which participant reads what;
- ``algorithms``: Jacobi, Gauss-Seidel, iterative (which participant steps when, seeing what);
- ``executors``: Python, threads, the native C stepper (``native``; how a stage is stepped);
  ``execution``: an algorithm carried out by executors;
- ``observers``: what watches a run (recorder, finite-value check, progress, your own);
  ``recorder``: recorded values and the RunResult;
- ``master``: :func:`run`, which composes them; ``runs``: a run written to disk (CSV + JSON
  sidecar, both or neither; the partial-file writer of a failed run);
- ``libcosim``: the same system run by libcosimpy, for cross-checks and benchmarks.

The engine imports ``rover_cosim.common`` only: no identification, no control, no FMU build.
The names below import on first use (``from rover_cosim.orchestrator import SystemBuilder, run``).
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

from rover_cosim.common.identity import require_root

require_root(__name__)

#: Public names and the module each comes from.
EXPORTS = {
    "System": "model", "Port": "model", "SystemFileError": "model", "Iteration": "model",
    "SystemBuilder": "builder", "replace_settings": "builder", "with_parameters": "builder",
    "load_system": "system", "system_to_toml": "system",
    "run": "master", "RunError": "participants", "RunResult": "recorder",
    "Observer": "observers", "StopWhen": "observers",
}


def __getattr__(name: str) -> Any:
    if name in EXPORTS:
        return getattr(import_module(f"{__name__}.{EXPORTS[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = sorted(EXPORTS)
