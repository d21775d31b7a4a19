"""The rover learns the soil it is on: the soil estimated from its own telemetry, and the
controller's longitudinal model identified again on that soil (issue 33, the online part).

``adapt_model`` is what a rover's controller calls at the end of its calibration phase:

1. the calibration samples (per wheel and sample: load W [N] from the body model, slip ratio from
   the wheel's spin and the body's speed, the driving torque Tx = tau - J domega/dt [N·m], and the
   sinkage [m] where the rover has a sensor) are steady-state single-wheel data
   (:class:`~rover_cosim.identification.testbed_data.TestBedData`), so
   :func:`~rover_cosim.identification.soil_estimation.estimate_soil` estimates the soil from them
   (starting from the soil the controller was identified on, the prior);
2. the paper's identification sweep (step torques on ``SingleWheel.fmu``, the torques of
   ``SweepPlan``, loads over the rover's own range: ``sweep_loads``) runs on the estimated soil
   and the wheel, in this process inside a pool's worker (a Monte Carlo run), else in a process
   of its own that a crash cannot take the caller down with, its runs kept in memory (or in a
   sweep cache where the caller gives one: a soil estimated again to the same values is then not
   run again), and ``fits.identify`` makes the model of the same degree the controller used, its
   Fx fit through the torques the closed loop drives with
   (``ADAPTED_FIT_TORQUE_MAX``).

The estimate searches the plan's parameters (c, φ, k_x, k_φ, n from the torques) and, unless asked
(``optional``), not the optional ones the ``estimate-soil`` command also tries in turn (the stress
distribution's a1, a0, λ, which then keep the prior's values): each of those is a search of its
own, several times the first one's evaluations, and 3 s of calibration telemetry rarely
determines them beside the others. Measured on 16 samples of the lunar study (``montecarlo
--adapt --runs 16``): the estimates 6.2x as fast, the whole command 32.4 -> 22.3 s; the largest
RMS(Fx - Fx_des) after the calibration the same (to 1e-6 N) in 10 samples, lower in 5 (by up to
0.011 N), higher in 1 (0.71 -> 0.79 N), the median 0.312 N either way.

What the telemetry cannot give: the drawbar pull of each wheel (a rover measures none), so the
estimate rests on the torques (and the sinkage with a sensor). Noise-free telemetry determines
the soil's forces well without a sinkage sensor; k_c and k_phi are never separated by one wheel
width (k_phi carries the modulus; the forces depend only on k_c/b + k_phi).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rover_cosim.terramechanics import Soil, Wheel

from .fits import FIT_TORQUE_MAX, IdentifiedModel, identify, step_table
from .lateral import LATERAL_SAMPLE_TIME, LATERAL_SLIP_ANGLES_DEG, LateralModel, identify_lateral, lateral_table
from .plan import torques_for
from .soil_estimation import SoilEstimate, estimate_soil
from .sweep import SweepPlan, run_sweep
from .testbed_data import TestBedData

#: N·m: the Fx(slip) fit of a model identified again uses the settled points up to this torque, the
#: range the closed loop drives with once it has left the start (the paper's identification fits up
#: to 40 N·m, the open-loop run's range). Measured on two soils far from the paper's (c 150 Pa,
#: phi 45 deg, k_phi 3e5; c 2.5 kPa, phi 31 deg, k_phi 5e6) with the true soil: the largest
#: RMS(Fx - Fx_des) after the calibration 2.0 -> 1.0 N and 0.74 -> 0.74 N.
ADAPTED_FIT_TORQUE_MAX = 20.0
FloatArray = NDArray[np.float64]

#: The loads [N] of the sweep identified again: LOAD_POINTS from LOAD_SPAN[0] x the smallest to
#: LOAD_SPAN[1] x the largest load of the calibration (the rover's own range with a margin for
#: the loads it meets later), instead of the paper's 100-800 N: the model's load dependence is a
#: quadratic in W fitted across the sweep's loads, so a sweep over the loads the rover runs at fits
#: them closely. Measured with the true soil on a soft sample of the lunar study (c 431 Pa, phi
#: 32.4 deg, k_phi 2.5e5, n 0.89), the largest RMS(Fx - Fx_des) 4-10 s after the start: 3.3 N with
#: 7 loads over 0.6-1.5x the calibration's, 1.1 N over 0.75-1.3x, 0.3 N with 8 loads over ~0.8-1.2x.
LOAD_SPAN = (0.8, 1.2)
LOAD_POINTS = 8


@dataclass(frozen=True)
class Adaptation:
    """What the adaptation found: the soil estimate, the model identified on it, and what it cost.

    Attributes:
        estimate: the soil estimated from the calibration data.
        model: the longitudinal model identified on the estimated soil.
        rows: calibration samples used.
        estimate_seconds: wall time of the estimate [s].
        identify_seconds: wall time of the sweep and fits [s].
        runs_computed: sweep runs computed (the others came from the cache).
        lateral: the lateral model identified on the estimated soil (None: not asked for).
    """

    estimate: SoilEstimate
    model: IdentifiedModel
    rows: int
    estimate_seconds: float
    identify_seconds: float
    runs_computed: int
    lateral: LateralModel | None = None

    @property
    def soil(self) -> Soil:
        """The estimated soil."""
        return self.estimate.soil


def sweep_loads(loads: FloatArray) -> tuple[float, ...]:
    """The loads [N] of the sweep identified again for a rover that measured ``loads`` [N]."""
    low, high = LOAD_SPAN[0] * float(np.min(loads)), LOAD_SPAN[1] * float(np.max(loads))
    return tuple(float(round(w)) for w in np.linspace(max(low, 1.0), max(high, low + LOAD_POINTS), LOAD_POINTS))


def identify_on_soil(fmu_path: Path, soil: Soil, wheel: Wheel, cache_dir: Path | None, degree: int,
                     plan: SweepPlan | None = None, torque_max: float = ADAPTED_FIT_TORQUE_MAX,
                     workers: int | None = 1) -> tuple[IdentifiedModel, int]:
    """The paper's longitudinal model (LUTs and the Fx fit of ``degree``) identified by the sweep on
    ``fmu_path`` (SingleWheel.fmu) with ``soil`` and ``wheel`` as its parameters (the runs cached in
    ``cache_dir``; None: kept in memory), the Fx fit through
    the points up to ``torque_max`` [N·m] (ADAPTED_FIT_TORQUE_MAX for the paper's wheel; a plan
    scaled to another wheel scales it too); the sweep on one process (``workers`` 1: an adaptive
    run; in this process where it is a pool's worker, a Monte Carlo run) or on ``workers``
    processes (None: every core; a command's own identification); (the model, the runs computed)."""
    plan = replace(plan or SweepPlan(), soil=soil, wheel=wheel)
    sweep = run_sweep(Path(fmu_path), plan, cache_dir, workers=workers)
    if not sweep.runs:
        raise RuntimeError(f"every run of the sweep on the estimated soil failed; first error: "
                           f"{next(iter(sweep.failures.values()))}")
    return identify(step_table(sweep.at_slip_angle(0.0)), degree, torque_max), sweep.computed


def identify_lateral_on_soil(fmu_path: Path, soil: Soil, wheel: Wheel, cache_dir: Path | None,
                             loads: tuple[float, ...], torques: tuple[float, ...] | None = None,
                             torque_max: float = FIT_TORQUE_MAX, workers: int | None = 1) -> tuple[LateralModel, int]:
    """The lateral model (the recommended form) identified by the lateral sweep on ``fmu_path``
    with ``soil`` and ``wheel`` at ``loads`` [N] and ``torques`` [N·m] (None: the paper's), fitted
    up to ``torque_max`` [N·m], the sweep on ``workers`` as ``identify_on_soil``'s; (the model, the
    runs computed)."""
    plan = SweepPlan(loads=loads, slip_angles_deg=LATERAL_SLIP_ANGLES_DEG, sample_time=LATERAL_SAMPLE_TIME,
                     soil=soil, wheel=wheel)
    if torques is not None:
        plan = replace(plan, torques=tuple(torques))
    sweep = run_sweep(Path(fmu_path), plan, cache_dir, workers=workers)
    if not sweep.runs:
        raise RuntimeError(f"every run of the lateral sweep on the estimated soil failed; first error: "
                           f"{next(iter(sweep.failures.values()))}")
    return identify_lateral(lateral_table(sweep.runs), torque_max=torque_max), sweep.computed


def adapt_model(data: TestBedData, fmu_path: Path, wheel: Wheel, prior: Soil, cache_dir: Path | None,
                degree: int, lateral: bool = False, optional: bool = False) -> Adaptation:
    """The soil estimated from ``data`` (from ``prior``), and the longitudinal model of ``degree``
    identified on it with ``fmu_path`` (SingleWheel.fmu); with ``lateral``, the lateral model too
    (the soil's lateral moduli, which torques do not show, kept at the prior's); with ``optional``
    the estimate also tries the plan's optional parameters (the stress distribution's a1, a0 and λ);
    see the module docstring."""
    started = time.perf_counter()
    estimate = estimate_soil(data, wheel, prior, optional=optional)
    estimated = time.perf_counter()
    loads = sweep_loads(data.load_N)
    torques, fit_max = torques_for(estimate.soil, wheel, loads)  # the paper's for the paper's wheel
    model, computed = identify_on_soil(fmu_path, estimate.soil, wheel, cache_dir, degree,
                                       SweepPlan(loads=loads, torques=torques),
                                       ADAPTED_FIT_TORQUE_MAX / FIT_TORQUE_MAX * fit_max)
    lateral_model = None
    if lateral:
        lateral_model, more = identify_lateral_on_soil(fmu_path, estimate.soil, wheel, cache_dir, loads, torques,
                                                       fit_max)
        computed += more
    return Adaptation(estimate, model, len(data.load_N), estimated - started, time.perf_counter() - estimated,
                      computed, lateral_model)
