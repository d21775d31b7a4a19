"""Monte Carlo over soil uncertainty (``rover-cosim montecarlo``, ``make montecarlo``): study
files, seeded samples, one closed-loop run per sample, metrics, sensitivity ranking, figures;
``job.run_montecarlo`` puts them together and writes results/montecarlo/."""

from __future__ import annotations

from importlib import import_module
from typing import Any

#: The package's names and the module each comes from, imported when first asked for: the study's
#: check needs none of the job's imports (pandas, scipy, matplotlib: seconds before a refusal).
_EXPORTS = {"MonteCarloResult": "job", "run_montecarlo": "job", "Study": "study", "StudyError": "study",
            "load_study": "study"}

__all__ = ["MonteCarloResult", "Study", "StudyError", "load_study", "run_montecarlo"]


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        return getattr(import_module(f"{__name__}.{_EXPORTS[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
