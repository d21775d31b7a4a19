"""The chosen soil and wheel as parameters of the FMUs a job runs (no rebuild: the FMUs take
them as parameters), and the record a results folder keeps of them."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import fmpy

from rover_cosim.terramechanics.library import Choice, fmu_parameters


@lru_cache(maxsize=32)
def _parameter_names(fmu_path: str) -> frozenset[str]:
    return frozenset(v.name for v in fmpy.read_model_description(fmu_path).modelVariables
                     if v.causality == "parameter")


def soil_parameters(fmu_path: Path, choice: Choice | None) -> dict[str, float]:
    """The soil and wheel of ``choice`` that the FMU has as parameters (none for a body FMU, or
    without a choice)."""
    if choice is None:
        return {}
    names = _parameter_names(str(Path(fmu_path).resolve()))
    return {name: value for name, value in fmu_parameters(choice.soil, choice.wheel).items() if name in names}
