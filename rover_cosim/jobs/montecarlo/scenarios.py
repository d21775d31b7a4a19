"""The scenarios a Monte Carlo study runs, as objects: each its plant FMU and the FMUs its
controller needs besides, the metrics it caches, how long its run lasts, its system and its row
of metrics. A study names them (``scenarios = ["straight", "path"]``); ``--adapt`` adds each one's
adaptive variant. A new scenario is an instance here and its entry in ``RUN_SCENARIOS``.

The plants are those ``make simulate`` runs, built by the same functions (``jobs.simulate``,
``jobs.path_following``; imported when a run is built, so that reading a study stays light)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from rover_cosim.control.calibration import Calibration
from rover_cosim.identification.model_set import ModelSet
from rover_cosim.orchestrator.model import System
from rover_cosim.terramechanics.library import Choice

from .metrics import ADAPTED, ADAPTED_PATH, PATH, STRAIGHT, path_metrics, straight_metrics

#: The path scenario of a study: the lane change at 1.0 m/s (the paper's speed).
PATH_SCENARIO = "lane_change"


@dataclass(frozen=True)
class RunScenario:
    """One scenario of a study: ``name``; ``fmu``: its plant (in the FMU folder); ``columns``: the
    metrics a run caches (its cache file's columns, ``wall_s`` after them); ``adapted_from``: the
    scenario this is the adaptive variant of (None: the identified model, unchanged); ``extra_fmus``:
    FMUs its controller needs besides the plant (the adaptive controllers identify their models again
    on SingleWheel.fmu); ``straight``: the paper's straight run (else the lane change)."""

    name: str
    fmu: str
    columns: tuple[str, ...]
    straight: bool
    adapted_from: str | None = None
    extra_fmus: tuple[str, ...] = ()

    def stop_time(self, straight_stop_time: float, path_stop_time: float | None) -> float:
        """s: how long a run lasts: a study's ``straight_stop_time`` [s], or its ``path_stop_time`` [s]
        (None: until the path's reference reaches its end)."""
        if self.straight:
            return straight_stop_time
        from rover_cosim.jobs import path_following

        return path_stop_time or path_following.stop_time(PATH_SCENARIO)

    def system(self, fmu_dir: Path, model: ModelSet, choice: Choice, calibration: Calibration) -> System:
        """The run's system before the sample's FMU parameters: the plant of ``fmu_dir`` and the
        controller with ``model`` on the sample's soil and wheel (``choice``); an adaptive one with
        ``calibration``, its sweeps' runs kept in memory (the soil is the run's own estimate, which
        no other run shares)."""
        from rover_cosim.jobs import path_following, simulate

        if self.straight and self.adapted_from:
            return simulate.adaptive_system(fmu_dir, model, choice, calibration=calibration, cache_dir=None)
        if self.straight:
            return simulate.monolithic_system(fmu_dir, model, choice)
        if self.adapted_from:
            return path_following.adaptive_system(fmu_dir, model, PATH_SCENARIO, choice, calibration=calibration,
                                                  cache_dir=None)
        return path_following.monolithic_system(fmu_dir, model, PATH_SCENARIO, "inverse", choice)

    def metrics(self, data: pd.DataFrame, window: float) -> dict[str, Any]:
        """The run's metrics from its recorded ``data`` (``window`` [s]: the calibration, after which
        the RMS is taken again)."""
        from rover_cosim.jobs import path_following, simulate

        if self.straight:
            return straight_metrics(simulate.trajectories(data, "monolithic"), calibration=window)
        table = path_following.trajectories(data, cosim=False)
        return path_metrics(table, path_following.metrics(table, path_following.SCENARIOS[PATH_SCENARIO]), window)

    @property
    def fmus(self) -> tuple[str, ...]:
        """Every FMU a run needs: the plant, then the extra ones."""
        return (self.fmu, *self.extra_fmus)


#: The scenarios by name: "straight" (paper Sec. 4, Rover.fmu), "path" (the lane change,
#: SteerableRover.fmu), and each with the adaptive controller.
RUN_SCENARIOS: dict[str, RunScenario] = {s.name: s for s in (
    RunScenario("straight", "Rover.fmu", STRAIGHT, straight=True),
    RunScenario("path", "SteerableRover.fmu", PATH, straight=False),
    RunScenario("straight_adapted", "Rover.fmu", ADAPTED, straight=True, adapted_from="straight",
                extra_fmus=("SingleWheel.fmu",)),
    RunScenario("path_adapted", "SteerableRover.fmu", ADAPTED_PATH, straight=False, adapted_from="path",
                extra_fmus=("SingleWheel.fmu",)),
)}
#: The scenario ``--adapt`` adds beside each that has an adaptive variant.
ADAPTIVE_VARIANT = {s.adapted_from: s.name for s in RUN_SCENARIOS.values() if s.adapted_from}

__all__ = ["ADAPTIVE_VARIANT", "PATH_SCENARIO", "RUN_SCENARIOS", "RunScenario"]
