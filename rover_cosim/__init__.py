"""rover-cosim: planetary-rover terramechanics in Modelica, FMI 2.0 and Python (after Yoshikawa et al.).

Subpackages, bottom layer first (each imports only the ones before it, see README "Architecture"):

- ``rover_cosim.common``: result writing with provenance, units, the paper's constants;
- ``rover_cosim.terramechanics``: the pure-numpy reference wheel;
- ``rover_cosim.fmubuild``: Modelica -> FMI 2.0 FMU exporter and its C runtime;
- ``rover_cosim.orchestrator``: the co-simulation engine (system files, participants, masters);
- ``rover_cosim.identification``: step-torque sweeps, fits, identified models;
- ``rover_cosim.control``: controllers as engine blocks;
- top: ``rover_cosim.cli`` (the ``rover-cosim`` command), ``rover_cosim.jobs`` (the pipeline
  jobs behind the Makefile targets), ``rover_cosim.report``.

``import rover_cosim`` loads nothing but the version: every subpackage is imported on use.
"""

from importlib import metadata as _metadata

try:
    __version__: str = _metadata.version("rover-cosim")
except _metadata.PackageNotFoundError:  # a checkout that was never installed
    __version__ = "0+unknown"

__all__ = ["__version__"]
