"""Monte Carlo over soil uncertainty (``rover-cosim montecarlo``, ``make montecarlo``): study
files, seeded samples, one closed-loop run per sample, metrics, sensitivity ranking, figures;
``job.run_montecarlo`` puts them together and writes results/montecarlo/."""

from __future__ import annotations

from .job import MonteCarloResult, run_montecarlo
from .study import Study, StudyError, load_study

__all__ = ["MonteCarloResult", "Study", "StudyError", "load_study", "run_montecarlo"]
