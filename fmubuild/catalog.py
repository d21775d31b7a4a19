"""Which Modelica classes become FMUs: the classes of the package's ``FMUs`` sub-package, in its
``package.order``. Read here once, without importing the exporter (the command line's choices and
help use it), so that a new FMU is one new class file plus its line in that package.order."""

from __future__ import annotations

from functools import cache
from pathlib import Path

#: The folder that holds the top-level Modelica package (a rumoca source root): ``modelica/`` of
#: the repository, installed as package data ``rover_cosim/modelica``.
MODELICA_ROOT = Path(__file__).parent.parent / "modelica"
#: Name of the top-level Modelica package.
PACKAGE = "RoverTerramechanics"
#: Its sub-package of the FMU top levels: the class ``<PACKAGE>.<FMU_PACKAGE>.<name>`` is exported
#: as ``<name>.fmu`` with the model identifier ``<name>``.
FMU_PACKAGE = "FMUs"


def fmu_class(name: str) -> str:
    """The qualified Modelica class exported as the FMU ``name`` (``"Wheel"`` ->
    ``"RoverTerramechanics.FMUs.Wheel"``): the one place that maps an FMU to its class."""
    return f"{PACKAGE}.{FMU_PACKAGE}.{name}"  # read when called: a test may point the module elsewhere


@cache
def fmu_models() -> tuple[str, ...]:
    """The FMUs ``make fmus`` builds: the names in ``FMUs/package.order``, in its order (each a class
    file of that folder; ``tests/test_modelica_package.py`` checks the two agree)."""
    order = MODELICA_ROOT / PACKAGE / FMU_PACKAGE / "package.order"
    return tuple(line.strip() for line in order.read_text().splitlines() if line.strip())
