"""Soil parameters estimated from steady-state single-wheel data: which soil makes the reference
wheel (:func:`rover_cosim.terramechanics.wheel_state`, the same law as the FMUs) give the measured
drawbar pull, torque, sinkage and lateral force?

Method. Weighted nonlinear least squares, :func:`scipy.optimize.least_squares` with bounds: the
residual of each measurement is (model - data) / σ of its channel, σ given per channel or
estimated from the fit's own residuals (a fit with each channel scaled by 1 % of its range, then σ
of each channel from its residuals, and the fit again). The parameters are searched in a
well-scaled space: logarithms of c, k_c, k_φ, k_x, k_y (positive moduli over decades), φ in rad,
n, a0, a1, λ, k_x,β, k_y,β as they are. The bounds (``BOUNDS``) keep every trial soil physical
(a1 < a0 and a0 + a1 < 1 included): an unbounded step to a0 + a1 > 1 is not a soil the wheel can
be evaluated on, and a penalty would make the cost rough; they also keep the search away from
soils too soft to carry the data's loads (where a trial soil cannot carry a row, that row's
residual is a large constant). The method is ``dogbox`` (a trust region that fixes the variables
on a bound): cohesion often ends on its lower bound (1 Pa) on sands, where the reflective ``trf``
crawled (up to 6000 evaluations against 300). The model is the wheel itself, vectorised over
the rows: one evaluation of 55 rows takes about 1.8 ms; a fit a median of 250 (benchmarks/bench_soil_estimation.py).

Uncertainty. At the optimum, the Jacobian J of the weighted residuals (central differences),
the Gauss-Newton covariance s² (JᵀJ)⁻¹ with s² the residual variance (sum of squares / (m - p)),
and intervals z ± t·sd in the search space (Student's t, m - p degrees of freedom), mapped back
(asymmetric for the logarithms). Identifiability: the singular values of J with unit columns and
Brun's collinearity index 1/σ_min (Brun, Reichert, Künsch, Water Resources Research 37(4),
2001: above ~15 the set is poorly identifiable), the correlation matrix, pairs beyond 0.95 named
in words, the least determined combination, and per parameter whether the data determine it.

What the data can determine (the plan, :func:`plan_parameters`): see ``docs/guide/soil-estimation.md``.
Briefly: k_c and k_φ enter the wheel only through k_c/b + k_φ, so one wheel width never
separates them (k_c is kept at the prior's, k_φ carries the modulus, and the estimate reports the
combined modulus); c, φ and k_x need a force or torque; a0, a1, λ (the stress distribution)
and the slip-angle growth of the moduli are tried and kept only if the data determine them;
k_y needs Fy at a slip angle other than 0.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rover_cosim.terramechanics import Soil, Wheel
from rover_cosim.terramechanics.parameters import UNITS, xc_from_phi

from .testbed_data import CHANNELS, FloatArray, Prediction, TestBedData, predict


@dataclass(frozen=True)
class ParameterSpec:
    """How a soil parameter is searched and judged.

    Attributes:
        name: the Soil field.
        words: what it is, for messages.
        log: searched as its logarithm (a positive modulus over decades).
        low, high: the bounds of the search [SI].
        step: a typical change in the search space (least_squares' x_scale).
        resolution: the width of the interval (in the search space: a ratio's logarithm, or SI)
            beyond which the data are said to determine the parameter poorly.
    """

    name: str
    words: str
    log: bool
    low: float
    high: float
    step: float
    resolution: float

    def to_search(self, value: float) -> float:
        return math.log(value) if self.log else float(value)

    def from_search(self, z: float) -> float:
        return math.exp(z) if self.log else float(z)


_FACTOR_4 = math.log(4.0)  # an interval from x/2 to 2x
#: The parameters the estimator may search, with their bounds (SI) and scales.
SPECS: dict[str, ParameterSpec] = {spec.name: spec for spec in (
    ParameterSpec("c", "cohesion c", True, 1.0, 5e4, 1.0, _FACTOR_4),
    ParameterSpec("phi", "friction angle φ", False, math.radians(5.0), math.radians(60.0), 0.1, math.radians(6.0)),
    ParameterSpec("kc", "cohesive modulus k_c", True, 1.0, 1e7, 1.0, _FACTOR_4),
    ParameterSpec("kphi", "frictional modulus k_φ", True, 1e3, 1e9, 1.0, _FACTOR_4),
    ParameterSpec("n", "sinkage exponent n", False, 0.2, 2.0, 0.1, 0.4),
    ParameterSpec("kx", "shear modulus k_x", True, 1e-4, 0.3, 1.0, _FACTOR_4),
    ParameterSpec("a0", "stress-angle constant a0", False, 0.25, 0.6, 0.1, 0.15),
    ParameterSpec("a1", "stress-angle slip coefficient a1", False, 0.0, 0.24, 0.1, 0.15),
    ParameterSpec("lam", "exit-angle ratio λ", False, 0.3, 1.0, 0.1, 0.15),
    ParameterSpec("ky", "lateral shear modulus k_y", True, 1e-4, 0.3, 1.0, _FACTOR_4),
    ParameterSpec("ky_beta", "growth of k_y with the slip angle", False, 0.0, 0.3, 0.01, 0.02),
    ParameterSpec("kx_beta", "growth of k_x with the slip angle", False, 0.0, 0.3, 0.01, 0.02),
    ParameterSpec("n_slip", "slip-sinkage growth of n (n + n_slip |s|)", False, 0.0, 2.0, 0.1, 0.2),
)}
#: The search bounds of each parameter [SI]: (low, high).
BOUNDS = {name: (spec.low, spec.high) for name, spec in SPECS.items()}
#: |correlation| above which two estimated parameters are said to trade off.
CORRELATION_LIMIT = 0.95
#: Residual of a row the trial soil cannot carry (in noise scales).
UNCARRIED_RESIDUAL = 1e3
#: Relative tolerances of the sinkage solve inside the fit, and of least_squares.
SOLVE_RTOL = 1e-12
FIT_TOL = 1e-10
METHOD = "dogbox"
#: The plan's statement about the optional stress-distribution parameters (left out of an estimate
#: that did not search them).
PATCH_STATEMENT = ("a0, a1 (the angle of the largest normal stress) and λ (the exit angle) are estimated only if "
                   "the data determine them; otherwise kept at the prior's values with the reason.")
#: Why an optional parameter kept the prior's value when the estimate was asked for the plan's only.
NOT_SEARCHED = "not searched: the estimate was asked for the plan's parameters only (optional ones off)"
#: Measurements per estimated parameter at least.
MEASUREMENTS_PER_PARAMETER = 2


@dataclass(frozen=True)
class FixedParameter:
    """A soil parameter the estimate keeps at the prior's value, and why."""

    name: str
    value: float
    reason: str


@dataclass(frozen=True)
class ParameterPlan:
    """Which parameters an estimate searches: ``estimated`` always, ``optional`` only while the
    data determine them (they are fixed, with the reason, when not), ``fixed`` at the prior's
    value with the reason; ``statements``: what the data's columns allow, in words."""

    estimated: tuple[str, ...]
    optional: tuple[str, ...]
    fixed: tuple[FixedParameter, ...]
    statements: tuple[str, ...]


def _distinct(values: FloatArray) -> int:
    return len(np.unique(np.round(values, 9)))


def plan_parameters(data: TestBedData, prior: Soil = Soil(), parameters: Sequence[str] | None = None,
                    wheel: Wheel = Wheel()) -> ParameterPlan:
    """What an estimate from ``data`` searches. ``parameters`` None: the default plan from the
    data's columns (see the module docstring); else exactly those (names of :data:`SPECS`),
    refused with a message if the data cannot show them at all (e.g. c without a force or torque
    column, k_y without Fy at a slip angle)."""
    facts = _Facts.of(data)
    if parameters is not None:
        return _requested(parameters, facts, prior, wheel)
    estimated: list[str] = []
    optional: list[str] = []
    fixed: dict[str, str] = {}
    statements: list[str] = []
    _plan_shear(facts, estimated, fixed, statements)
    _plan_pressure(facts, estimated, fixed, statements, wheel)
    _plan_patch(facts, optional, fixed, statements)
    _plan_lateral(facts, estimated, optional, fixed, statements)
    _plan_slip_sinkage(facts, prior, estimated, fixed, statements)
    _plan_grousers(wheel, statements)
    return ParameterPlan(tuple(estimated), tuple(optional),
                         tuple(FixedParameter(name, getattr(prior, name), reason) for name, reason in fixed.items()),
                         tuple(statements))


@dataclass(frozen=True)
class _Facts:
    """What the data's columns and inputs allow."""

    force: bool  # Fx_N or Tx_Nm
    sinkage: bool
    lateral: bool  # Fy_N at some slip angle != 0
    loads: int  # distinct loads
    angles_force: int  # distinct |slip angle| among rows (with a force column)
    angles_lateral: int  # distinct |slip angle| != 0
    slips: int  # the most distinct |slip| at one load

    @staticmethod
    def of(data: TestBedData) -> _Facts:
        beta = np.abs(data.slip_angle_rad)
        force = data.Fx_N is not None or data.Tx_Nm is not None
        lateral = data.Fy_N is not None and bool(np.any(beta > 0))
        slips = max(_distinct(np.abs(data.slip[data.load_N == load])) for load in np.unique(data.load_N))
        return _Facts(force, data.sinkage_m is not None, lateral, _distinct(data.load_N),
                      _distinct(beta) if force else 0, _distinct(beta[beta > 0]) if lateral else 0, slips)


def _plan_shear(facts: _Facts, estimated: list[str], fixed: dict[str, str], statements: list[str]) -> None:
    if not facts.force:
        for name in ("c", "phi", "kx"):
            fixed[name] = "no Fx_N or Tx_Nm column: the shear strength and its build-up need a force or torque"
        statements.append("No Fx_N or Tx_Nm: c, φ and k_x cannot be estimated (sinkage alone hardly sees the shear "
                          "strength); kept at the prior's values.")
        return
    if facts.loads < 2:
        fixed["c"] = ("every row at one load: c (shear strength c·b·L) and φ (W·tan φ) cannot be told apart; "
                      "φ carries the strength")
        statements.append("One load only: c is kept at the prior's value and φ carries the whole shear strength; "
                          "measure at several loads to separate them.")
        estimated += ["phi", "kx"]
    else:
        estimated += ["c", "phi", "kx"]


def _plan_pressure(facts: _Facts, estimated: list[str], fixed: dict[str, str], statements: list[str],
                   wheel: Wheel) -> None:
    fixed["kc"] = (f"k_c and k_φ enter the wheel only through k_c/b + k_φ (b = {wheel.b:g} m): one wheel width "
                   "cannot separate them; k_φ carries the modulus")
    statements.append(f"k_c and k_φ act only as k_c/b + k_φ for the wheel's width b = {wheel.b:g} m: k_c is kept "
                      "at the prior's value, k_φ carries the combined modulus (reported as bekker_modulus); data of a "
                      "second wheel width would separate them.")
    if facts.loads < 2:
        fixed["n"] = "every row at one load: the sinkage exponent n needs the sinkage's growth with the load"
        statements.append("One load only: n is kept at the prior's value.")
    estimated.append("kphi")
    if facts.loads >= 2:
        estimated.append("n")
    if not facts.sinkage:
        statements.append("No sinkage_m: k_φ and n are seen only through their effect on the forces and trade off "
                          "(expect a strong correlation and wide intervals); the sinkage the estimate predicts is "
                          "the least certain of its outputs.")


def _plan_patch(facts: _Facts, optional: list[str], fixed: dict[str, str], statements: list[str]) -> None:
    if facts.force or facts.sinkage:
        optional += ["a1", "a0", "lam"]
        statements.append(PATCH_STATEMENT)
    else:  # only Fy: plan_parameters adds the lateral ones
        for name in ("a0", "a1", "lam"):
            fixed[name] = "no Fx_N, Tx_Nm or sinkage_m column"


def _plan_lateral(facts: _Facts, estimated: list[str], optional: list[str], fixed: dict[str, str],
                  statements: list[str]) -> None:
    if not facts.lateral:
        for name in ("ky", "ky_beta", "kx_beta"):
            fixed[name] = "no Fy_N at a slip angle other than 0: the lateral moduli need the lateral force"
        statements.append("No Fy_N at a slip angle other than 0: the lateral moduli k_y, k_y,β and k_x,β are kept at "
                          "the prior's values.")
        return
    estimated.append("ky")
    if facts.angles_lateral >= 2:
        optional.append("ky_beta")
    else:
        fixed["ky_beta"] = "Fy_N at one slip angle only: the growth of k_y with the angle needs two or more"
    if facts.force and facts.angles_force >= 2:
        optional.append("kx_beta")
    else:
        fixed["kx_beta"] = "forces at one slip angle only: the growth of k_x with the angle needs two or more"
    statements.append("The sidewall's ρ and X_c are not estimated (the sidewall is a small part of Fy under lunar "
                      "gravity); X_c follows the estimated φ where the prior derives it from φ.")


#: Distinct |slip| at one load that slip-sinkage needs: its growth of the exponent beside n itself.
SLIP_SINKAGE_SLIPS = 3


def _plan_slip_sinkage(facts: _Facts, prior: Soil, estimated: list[str], fixed: dict[str, str],
                       statements: list[str]) -> None:
    """Slip-sinkage (Soil.n_slip) is estimated where the prior has it on (n_slip > 0: the user's
    choice of the model) and the data show a load at several slips; off, nothing changes."""
    if prior.n_slip == 0:
        return
    if facts.slips < SLIP_SINKAGE_SLIPS or not (facts.sinkage or facts.force):
        fixed["n_slip"] = (f"slip-sinkage on (the prior's n_slip = {prior.n_slip:g}) but no load measured at "
                           f"{SLIP_SINKAGE_SLIPS} or more slips: its growth of the exponent with slip needs them")
        return
    estimated.append("n_slip")
    statements.append(f"Slip-sinkage on (the prior's n_slip = {prior.n_slip:g}): n_slip is estimated from how the "
                      "sinkage and the forces change with slip at a fixed load" + (
                          "." if facts.sinkage else "; without sinkage_m it is seen only through the compaction "
                          "resistance and trades off with n and k_φ (expect wide intervals)."))


def _plan_grousers(wheel: Wheel, statements: list[str]) -> None:
    """What a grousered wheel means for the estimate (its grousers are the wheel's, not estimated)."""
    if not wheel.grousered:
        return
    statements.append(f"The wheel's grousers ({wheel.grouser_count:g} of {1000 * wheel.grouser_height:g} mm) are "
                      "part of the model (terramechanics.grousers: the soil sheared at the grousers' tips and on the "
                      "trapped soil's sides); c, φ and k_x are the soil's under that model. The grouser model's own "
                      "assumptions (how many grousers engage) are not estimated: a smooth wheel's fit to these data "
                      "would put the grousers' thrust into c and φ.")


def _requested(parameters: Sequence[str], facts: _Facts, prior: Soil, wheel: Wheel) -> ParameterPlan:
    names = [str(p).strip() for p in parameters]
    unknown = [p for p in names if p not in SPECS]
    if unknown:
        raise ValueError(f"parameter {unknown[0]!r}: expected some of {', '.join(SPECS)}")
    twice = [p for k, p in enumerate(names) if p in names[:k]]
    if twice or not names:
        raise ValueError(f"parameters {names}: expected one or more distinct names" + (f" ({twice[0]} twice)"
                                                                                        if twice else ""))
    needs = {"c": facts.force, "phi": facts.force, "kx": facts.force, "ky": facts.lateral,
             "ky_beta": facts.angles_lateral >= 2, "kx_beta": facts.force and facts.angles_force >= 2,
             "n_slip": facts.slips >= SLIP_SINKAGE_SLIPS and (facts.sinkage or facts.force)}
    why = {"c": "a Fx_N or Tx_Nm column", "phi": "a Fx_N or Tx_Nm column", "kx": "a Fx_N or Tx_Nm column",
           "ky": "Fy_N at a slip angle other than 0", "ky_beta": "Fy_N at two or more slip angles other than 0",
           "kx_beta": "Fx_N or Tx_Nm at two or more slip angles",
           "n_slip": f"a load measured at {SLIP_SINKAGE_SLIPS} or more slips (sinkage or forces)"}
    for name in names:
        if not needs.get(name, True):
            raise ValueError(f"parameter {name} ({SPECS[name].words}) cannot be estimated from these data: it needs "
                             f"{why[name]}")
    statements = []
    if "kc" in names and "kphi" in names:
        statements.append(f"k_c and k_φ both asked: they act only as k_c/b + k_φ (b = {wheel.b:g} m), so the data "
                          "cannot separate them; see their intervals.")
    _plan_grousers(wheel, statements)
    fixed = tuple(FixedParameter(name, getattr(prior, name), "not asked (--parameters)")
                  for name in SPECS if name not in names and (name != "n_slip" or prior.n_slip != 0))
    return ParameterPlan(tuple(names), (), fixed, tuple(statements))


@dataclass(frozen=True)
class ParameterEstimate:
    """One estimated soil parameter (SI; φ in rad) and its interval.

    Attributes:
        name: the Soil field.
        value: the estimate.
        low, high: the interval at the estimate's confidence level (NaN where the data do not
            determine the parameter at all).
        standard_error: the standard deviation in the search space: relative (of the logarithm)
            for c, k_c, k_φ, k_x, k_y; SI for the others.
        prior: the prior soil's value (the search's start).
        determined: "well", "poorly" (interval wider than the parameter's resolution) or "not"
            (a combination of parameters the data do not see at all).
        at_bound: the estimate lies on a bound of the search (its interval is then unreliable).
    """

    name: str
    value: float
    low: float
    high: float
    standard_error: float
    prior: float
    determined: str
    at_bound: bool

    @property
    def unit(self) -> str:
        return UNITS.get(self.name, "")

    def text(self) -> str:
        """"phi = 35.1 deg [34.7, 35.5] (well determined)"."""
        scale, unit = (180 / math.pi, " deg") if self.name == "phi" else (1.0, f" {self.unit}" * (self.unit != "1"))
        interval = ("[not determined]" if math.isnan(self.low)
                    else f"[{self.low * scale:.4g}, {self.high * scale:.4g}]")
        note = f"{self.determined} determined" + (", at a bound of the search" if self.at_bound else "")
        return f"{self.name} = {self.value * scale:.4g}{unit} {interval} ({note})"


@dataclass(frozen=True)
class ChannelResiduals:
    """One measured channel at the estimate: data, model, residuals (model - data) and its noise
    scale σ (given, or estimated from the residuals)."""

    channel: str
    measured: FloatArray
    fitted: FloatArray
    noise_scale: float
    noise_given: bool

    @property
    def residuals(self) -> FloatArray:
        return self.fitted - self.measured

    @property
    def rms(self) -> float:
        return float(np.sqrt(np.mean(self.residuals**2)))


@dataclass(frozen=True)
class CorrelatedPair:
    """Two estimated parameters whose estimates trade off (|correlation| > 0.95), and why in words."""

    first: str
    second: str
    correlation: float
    statement: str


@dataclass(frozen=True)
class Identifiability:
    """What the data determine.

    Attributes:
        singular_values: of the weighted Jacobian with unit columns, largest first.
        collinearity_index: 1 / the smallest of them (Brun et al. 2001; above ~15: poorly identifiable set).
        correlated: the pairs that trade off.
        weakest: the least determined combination of the searched parameters (unit vector in the
            search space, the components above 0.1).
        statements: in words: what the columns allow, what trades off, what is poorly or not determined.
    """

    singular_values: tuple[float, ...]
    collinearity_index: float
    correlated: tuple[CorrelatedPair, ...]
    weakest: dict[str, float]
    statements: tuple[str, ...]


@dataclass(frozen=True)
class SoilEstimate:
    """The soil estimated from test-bed data, with its uncertainty and what the data determine.

    Attributes:
        soil: the estimated soil (the prior's values for everything not estimated).
        prior: the prior soil (start of the search, values of what was not estimated).
        wheel: the wheel of the data.
        data: the data.
        parameters: the estimated parameters by name, in search order.
        fixed: the parameters kept at the prior's value, by name, with the reason.
        correlation: correlation matrix of the estimates (order of ``parameters``).
        covariance: their covariance in the search space (logarithms for c, k_c, k_φ, k_x, k_y).
        residuals: per measured channel: data, model, residuals, noise scale.
        identifiability: what the data determine.
        bekker_modulus: k_c/b + k_φ [N/m^(n+2)] for the wheel's width, the modulus the data see.
        confidence: level of the intervals.
        evaluations: wheel-model evaluations (batches of all rows) the estimate took.
        seconds: its wall time.
        message: the optimizer's last word.
    """

    soil: Soil
    prior: Soil
    wheel: Wheel
    data: TestBedData
    parameters: dict[str, ParameterEstimate]
    fixed: dict[str, FixedParameter]
    correlation: FloatArray
    covariance: FloatArray
    residuals: dict[str, ChannelResiduals]
    identifiability: Identifiability
    bekker_modulus: ParameterEstimate
    confidence: float
    evaluations: int
    seconds: float
    message: str = ""
    notes: tuple[str, ...] = field(default=())

    def interval(self, name: str) -> tuple[float, float]:
        """(low, high) of an estimated parameter [SI]; KeyError naming the estimated ones."""
        if name not in self.parameters:
            raise KeyError(f"{name} was not estimated (estimated: {', '.join(self.parameters)})")
        estimate = self.parameters[name]
        return estimate.low, estimate.high

    def predict(self, load_N: ArrayLike, slip: ArrayLike, slip_angle_deg: ArrayLike = 0.0) -> Prediction:
        """The estimated soil's wheel at other loads and slips (testbed_data.predict)."""
        return predict(self.soil, self.wheel, load_N, slip, slip_angle_deg)

    def summary(self) -> str:
        """A few lines for a person: the estimates, what is kept at the prior, the residuals and
        what the data determine, in words."""
        lines = [f"estimated from {self.data.rows} rows ({', '.join(self.data.channels)}) in {self.seconds:.2f} s "
                 f"({self.evaluations} wheel evaluations); {100 * self.confidence:g} % intervals:"]
        lines += [f"  {estimate.text()}" for estimate in self.parameters.values()]
        modulus = self.bekker_modulus
        lines.append(f"  k_c/b + k_φ = {modulus.value:.4g} N/m^(n+2) [{modulus.low:.4g}, {modulus.high:.4g}]")
        kept = ", ".join(f"{f.name} = {f.value:.4g}" for f in self.fixed.values())
        lines.append(f"kept at the prior's values: {kept}")
        lines += [f"residual RMS {c.channel}: {c.rms:.3g} {CHANNELS[c.channel]} (noise scale {c.noise_scale:.3g}, "
                  f"{'given' if c.noise_given else 'estimated'})" for c in self.residuals.values()]
        lines += [f"- {s}" for s in self.identifiability.statements]
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """The estimate as JSON-able values (NaN as None), residuals per row."""
        def number(value: float) -> float | None:
            return None if not math.isfinite(value) else float(value)

        def estimate_dict(e: ParameterEstimate) -> dict[str, Any]:
            return {"value": e.value, "low": number(e.low), "high": number(e.high), "unit": e.unit,
                    "standard_error_search_space": number(e.standard_error),
                    "search_space": "log" if SPECS.get(e.name, SPECS["kphi"]).log else "linear",
                    "prior": e.prior, "determined": e.determined, "at_bound": e.at_bound}

        names = list(self.parameters)
        return {
            "soil": asdict(self.soil), "phi_deg": math.degrees(self.soil.phi), "prior": asdict(self.prior),
            "wheel": asdict(self.wheel), "confidence": self.confidence,
            "estimates": {name: estimate_dict(e) for name, e in self.parameters.items()},
            "bekker_modulus": estimate_dict(self.bekker_modulus),
            "fixed": {f.name: {"value": f.value, "reason": f.reason} for f in self.fixed.values()},
            "correlation": {"parameters": names, "matrix": [[number(v) for v in row] for row in self.correlation]},
            "identifiability": {
                "singular_values": [number(v) for v in self.identifiability.singular_values],
                "collinearity_index": number(self.identifiability.collinearity_index),
                "correlated_pairs": [asdict(p) for p in self.identifiability.correlated],
                "weakest_combination": self.identifiability.weakest,
                "statements": list(self.identifiability.statements)},
            "residuals": {c.channel: {"unit": CHANNELS[c.channel], "noise_scale": c.noise_scale,
                                      "noise_given": c.noise_given, "rms": c.rms,
                                      "residuals": [float(v) for v in c.residuals]}
                          for c in self.residuals.values()},
            "rows": self.data.rows, "evaluations": self.evaluations, "seconds": self.seconds, "message": self.message,
        }


class _Problem:
    """The weighted residuals of one data set as a function of the searched parameters."""

    def __init__(self, data: TestBedData, wheel: Wheel, prior: Soil, names: Sequence[str],
                 scales: Mapping[str, float]) -> None:
        self.data, self.wheel, self.prior = data, wheel, prior
        self.names = tuple(names)
        self.scales = dict(scales)
        self.evaluations = 0
        self.derive_xc = math.isclose(prior.xc, xc_from_phi(prior.phi), rel_tol=0, abs_tol=1e-12)

    def soil(self, z: NDArray[np.float64]) -> Soil:
        values = {name: SPECS[name].from_search(float(v)) for name, v in zip(self.names, z)}
        if self.derive_xc and "phi" in values:
            values["xc"] = xc_from_phi(values["phi"])
        return replace(self.prior, **values)

    def predict(self, z: NDArray[np.float64]) -> Prediction:
        self.evaluations += 1
        data = self.data
        return predict(self.soil(z), self.wheel, data.load_N, data.slip,
                       0.0 if data.slip_angle_deg is None else data.slip_angle_deg, SOLVE_RTOL)

    def residuals(self, z: NDArray[np.float64]) -> NDArray[np.float64]:
        prediction = self.predict(z)
        parts = []
        for name in self.data.channels:
            weighted = (prediction.channel(name) - self.data.channel(name)) / self.scales[name]
            parts.append(np.where(prediction.uncarried, UNCARRIED_RESIDUAL, weighted))
        return np.concatenate(parts)

    def jacobian(self, z: NDArray[np.float64], low: NDArray[np.float64],
                 high: NDArray[np.float64]) -> NDArray[np.float64]:
        """Central differences, a step of 1e-5 of each parameter's typical change (one-sided at a
        bound of the search)."""
        columns = []
        for k, name in enumerate(self.names):
            h = 1e-5 * SPECS[name].step
            up, down = z.copy(), z.copy()
            up[k] = min(z[k] + h, high[k])
            down[k] = max(z[k] - h, low[k])
            columns.append((self.residuals(up) - self.residuals(down)) / (up[k] - down[k]))
        return np.column_stack(columns) if columns else np.zeros((self.measurements, 0))

    @property
    def measurements(self) -> int:
        return self.data.rows * len(self.data.channels)


def _channel_scale(values: FloatArray) -> float:
    """A channel's size: its range, else its largest magnitude, else 1."""
    return float(np.ptp(values)) or float(np.max(np.abs(values))) or 1.0


def _noise_scales(data: TestBedData, noise: Mapping[str, float] | None) -> tuple[dict[str, float], set[str]]:
    """The starting σ of each channel (given, or 1 % of its range) and the names given."""
    given = dict(noise or {})
    for name, value in given.items():
        if name not in data.channels:
            raise ValueError(f"noise scale of {name!r}: expected a measured channel of the data "
                             f"({', '.join(data.channels)})")
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not (math.isfinite(value) and value > 0):
            raise ValueError(f"noise scale of {name} = {value!r}: expected a finite number > 0 ({CHANNELS[name]})")
    scales = {name: float(given.get(name, 0.01 * _channel_scale(data.channel(name)))) for name in data.channels}
    return scales, set(given)


def _check_fit_data(data: TestBedData, wheel: Wheel, plan: ParameterPlan) -> None:
    if data.sinkage_m is not None:
        deep = np.flatnonzero(data.sinkage_m >= wheel.r)
        if deep.size:
            row = int(deep[0])
            raise ValueError(f"{data.source}: {data.row_name(row)}, column sinkage_m: {float(data.sinkage_m[row])!r} "
                             f"m: expected a sinkage below the wheel's radius {wheel.r:g} m")
    least = MEASUREMENTS_PER_PARAMETER * len(plan.estimated) + 1
    if data.rows * len(data.channels) < least:
        raise ValueError(f"{data.source}: {data.rows} rows x {len(data.channels)} measured columns = "
                         f"{data.rows * len(data.channels)} measurements for {len(plan.estimated)} parameters "
                         f"({', '.join(plan.estimated)}): too few points; expected at least {least} "
                         f"({MEASUREMENTS_PER_PARAMETER} per parameter and one more)")


def _start(prior: Soil, names: Sequence[str], bounds: Mapping[str, tuple[float, float]]) -> tuple[
        NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The prior in the search space (moved inside the bounds) and the bounds there."""
    low = np.array([SPECS[n].to_search(bounds[n][0]) if bounds[n][0] > 0 or not SPECS[n].log else -np.inf
                    for n in names])
    high = np.array([SPECS[n].to_search(bounds[n][1]) for n in names])
    z0 = np.array([SPECS[n].to_search(getattr(prior, n)) if getattr(prior, n) > 0 or not SPECS[n].log else low[k]
                   for k, n in enumerate(names)])
    margin = 1e-9 * np.maximum(1.0, np.abs(high - low))
    return np.clip(z0, low + margin, high - margin), low, high


def _bounds(prior: Soil, given: Mapping[str, tuple[float, float]] | None) -> dict[str, tuple[float, float]]:
    """The search bounds: BOUNDS, those ``given``, widened to hold the prior's value."""
    bounds = dict(BOUNDS)
    for name, pair in (given or {}).items():
        if name not in SPECS:
            raise ValueError(f"bounds of {name!r}: expected a parameter of {', '.join(SPECS)}")
        low, high = (float(v) for v in pair)
        if not (math.isfinite(low) and math.isfinite(high) and low < high) or (SPECS[name].log and low <= 0):
            raise ValueError(f"bounds of {name} = {pair!r}: expected finite low < high" +
                             (" with low > 0" if SPECS[name].log else ""))
        bounds[name] = (low, high)
    for name, (low, high) in bounds.items():
        value = getattr(prior, name)
        bounds[name] = (min(low, value) if value > 0 or not SPECS[name].log else low, max(high, value))
    return bounds


def _t_quantile(probability: float, dof: float) -> float:
    """Student's t quantile: scipy.stats.t.ppf's bits from scipy.special's stdtrit, which it calls
    (scipy.stats is a second of imports, paid again by every worker process of a Monte Carlo that
    estimates soils); NaN for dof <= 0 as there."""
    from scipy.special import stdtrit

    return float(stdtrit(dof, probability)) if dof > 0 else math.nan


def _fit(problem: _Problem, z: NDArray[np.float64], low: NDArray[np.float64],
         high: NDArray[np.float64]) -> tuple[NDArray[np.float64], str]:
    if not problem.names:
        return z, "nothing to search"
    # imported here: a quarter of a second for every command that loads the adaptive controller
    from scipy import optimize

    steps = np.array([SPECS[name].step for name in problem.names])
    result = optimize.least_squares(problem.residuals, z, bounds=(low, high), method=METHOD, x_scale=steps,
                                    diff_step=1e-7, ftol=FIT_TOL, xtol=FIT_TOL, gtol=FIT_TOL, max_nfev=200)
    return np.asarray(result.x, dtype=float), str(result.message)


def _reestimate_noise(problem: _Problem, z: NDArray[np.float64], given: set[str]) -> bool:
    """σ of each channel not given from its residuals (sum of squares / its share of the degrees
    of freedom); whether any changed by more than 10 %."""
    residuals = problem.residuals(z)
    m, p = problem.measurements, len(problem.names)
    rows = problem.data.rows
    changed = False
    for k, name in enumerate(problem.data.channels):
        if name in given:
            continue
        part = residuals[k * rows:(k + 1) * rows] * problem.scales[name]
        dof = max(rows * (1 - p / m), 1.0)
        floor = 1e-9 * _channel_scale(problem.data.channel(name))
        sigma = max(float(np.sqrt(np.sum(part**2) / dof)), floor)
        changed |= not math.isclose(sigma, problem.scales[name], rel_tol=0.1)
        problem.scales[name] = sigma
    return changed


@dataclass(frozen=True)
class _Statistics:
    covariance: NDArray[np.float64]
    standard_errors: NDArray[np.float64]
    correlation: NDArray[np.float64]
    singular_values: NDArray[np.float64]
    directions: NDArray[np.float64]  # right singular vectors (columns), unit-column Jacobian
    unseen: NDArray[np.bool_]  # parameters in a direction the data do not see
    dof: int


def _statistics(problem: _Problem, z: NDArray[np.float64], low: NDArray[np.float64],
                high: NDArray[np.float64]) -> _Statistics:
    jacobian = problem.jacobian(z, low, high)
    residuals = problem.residuals(z)
    m, p = jacobian.shape
    dof = max(m - p, 1)
    variance = float(np.sum(residuals**2)) / dof
    norms = np.linalg.norm(jacobian, axis=0)
    unit = jacobian / np.where(norms > 0, norms, 1.0)
    _, singular, vt = np.linalg.svd(unit, full_matrices=False)
    null = singular < 1e-6 * max(float(singular[0]) if singular.size else 1.0, 1e-300)
    unseen = (norms == 0) | (np.any(np.abs(vt[null]) > 0.1, axis=0) if null.any() else np.zeros(p, dtype=bool))
    # covariance of z from the unit-column SVD: J = U S Vᵀ diag(norms)
    with np.errstate(divide="ignore", invalid="ignore"):
        inverse = np.where(null, 0.0, 1.0 / singular**2)
        scaled = (vt.T * inverse) @ vt
        seen = np.where(norms > 0, norms, np.inf)
        covariance = variance * scaled / np.outer(seen, seen)
        errors = np.sqrt(np.diag(covariance))
        correlation = covariance / np.outer(errors, errors)
    errors = np.where(unseen, np.nan, errors)
    correlation[unseen, :] = np.nan
    correlation[:, unseen] = np.nan
    np.fill_diagonal(correlation, 1.0)
    _mark_unseen_pairs(correlation, vt[null])
    return _Statistics(covariance, errors, correlation, singular, vt.T, unseen, dof)


def _mark_unseen_pairs(correlation: NDArray[np.float64], null_directions: NDArray[np.float64]) -> None:
    """Parameters sharing a direction the data do not see are perfectly correlated (±1)."""
    for direction in null_directions:
        members = np.flatnonzero(np.abs(direction) > 0.1)
        for i in members:
            for j in members:
                if i != j:
                    correlation[i, j] = float(np.sign(direction[i] * direction[j]))


def _estimates(problem: _Problem, z: NDArray[np.float64], statistics: _Statistics, low: NDArray[np.float64],
               high: NDArray[np.float64], confidence: float) -> dict[str, ParameterEstimate]:
    quantile = _t_quantile(0.5 + confidence / 2, statistics.dof)
    out = {}
    for k, name in enumerate(problem.names):
        spec = SPECS[name]
        error = float(statistics.standard_errors[k])
        margin = 1e-6 * max(1.0, float(high[k] - low[k]))
        at_bound = bool(z[k] - low[k] < margin or high[k] - z[k] < margin)
        if not math.isfinite(error):
            lo = hi = math.nan
            determined = "not"
        else:
            # the interval within the search's bounds (beyond them it is not a soil the search allows)
            lo = spec.from_search(max(z[k] - quantile * error, low[k]))
            hi = spec.from_search(min(z[k] + quantile * error, high[k]))
            determined = "poorly" if 2 * quantile * error > spec.resolution else "well"
        out[name] = ParameterEstimate(name, spec.from_search(float(z[k])), lo, hi, error, getattr(problem.prior, name),
                                      determined, at_bound)
    return out


def _pair_statement(first: str, second: str, r: float, wheel: Wheel, data: TestBedData) -> str:
    pair = {first, second}
    words = f"{SPECS[first].words} and {SPECS[second].words} trade off (correlation {r:+.3f})"
    loads = f"{data.load_N.min():g}-{data.load_N.max():g} N"
    if pair == {"c", "phi"}:
        return (f"{words}: cohesion adds c·b·L and friction W·tan φ to the shear strength, and over the data's loads "
                f"({loads}) the two grow alike; a wider range of loads separates them.")
    if pair == {"kc", "kphi"}:
        return f"{words}: they act only as k_c/b + k_φ for the one wheel width b = {wheel.b:g} m."
    if pair <= {"kc", "kphi", "n"}:
        return (f"{words}: both set how deep the wheel sinks, h ≈ (W/k)^(2/(2n+1)); the data determine the sinkage "
                f"they give together over {loads} better than either" + ("" if data.sinkage_m is not None else
                                                                         "; sinkage measurements would help") + ".")
    if pair <= {"a0", "a1", "lam", "kphi", "n", "kc"}:
        return f"{words}: both shape the normal stress under the wheel and so the sinkage and the forces."
    return f"{words}: the data determine a combination of them better than either."


def _plan_statements(plan: ParameterPlan, dropped: Sequence[FixedParameter], optional: bool) -> list[str]:
    """The plan's statements and one per optional parameter kept at the prior's value: tried and
    not determined, or (``optional`` False) not searched, when the plan's statement about them
    does not hold."""
    if optional:
        return [*plan.statements, *(f"{f.name} was tried and is kept at the prior's value: {f.reason}."
                                    for f in dropped)]
    return [*(s for s in plan.statements if s != PATCH_STATEMENT),
            *(f"{f.name} was not searched (optional parameters off) and is kept at the prior's value."
              for f in dropped)]


def _identifiability(problem: _Problem, statistics: _Statistics, estimates: Mapping[str, ParameterEstimate],
                     plan: ParameterPlan, dropped: Sequence[FixedParameter],
                     optional: bool = True) -> Identifiability:
    names = problem.names
    pairs = []
    for i in range(len(names)):
        for j in range(i):
            r = float(statistics.correlation[i, j])
            if math.isfinite(r) and abs(r) > CORRELATION_LIMIT:
                pairs.append(CorrelatedPair(names[j], names[i], r,
                                            _pair_statement(names[j], names[i], r, problem.wheel, problem.data)))
    singular = statistics.singular_values
    index = float(1 / singular[-1]) if singular.size and singular[-1] > 0 else math.inf
    weakest = {}
    if singular.size:
        direction = statistics.directions[:, -1]
        direction = direction * (1 if direction[np.argmax(np.abs(direction))] > 0 else -1)
        weakest = {(f"log {n}" if SPECS[n].log else n): round(float(v), 4)
                   for n, v in zip(names, direction) if abs(v) > 0.1}
    statements = _plan_statements(plan, dropped, optional)
    statements += [p.statement for p in pairs]
    for e in estimates.values():
        if e.determined == "not":
            statements.append(f"{SPECS[e.name].words} is not determined by these data (its value is where the "
                              "search stopped).")
        elif e.determined == "poorly":
            statements.append(f"{SPECS[e.name].words} is poorly determined: {e.text()}.")
        if e.at_bound:
            statements.append(f"{SPECS[e.name].words} ends on a bound of the search ({e.value:.4g} {e.unit}): the "
                              "data push it beyond; its interval does not hold.")
    if math.isfinite(index) and index > 15:
        statements.append(f"Collinearity index {index:.3g} (above ~15, Brun et al. 2001: the set is identified only "
                          "from precise data; the intervals above say how precise these are); the least determined "
                          f"combination is {_combination(weakest)}.")
    return Identifiability(tuple(float(s) for s in singular), index, tuple(pairs), weakest, tuple(statements))


def _combination(weakest: Mapping[str, float]) -> str:
    return " ".join(f"{v:+.2f}·{k}" for k, v in weakest.items())


def _rejection(problem: _Problem, statistics: _Statistics, estimates: Mapping[str, ParameterEstimate],
               name: str) -> str | None:
    """Why the data do not determine the optional parameter ``name`` beside the others searched
    (it trades off with one of them, ends on a bound, or its interval is wider than its
    resolution), or None if they do."""
    k = problem.names.index(name)
    estimate = estimates[name]
    others = [n for n in problem.names if n != name]
    correlations = np.abs(np.nan_to_num(np.delete(statistics.correlation[k], k), nan=1.0))
    if correlations.size and correlations.max() > CORRELATION_LIMIT:
        partner = others[int(np.argmax(correlations))]
        return (f"the data do not determine it: it trades off with {SPECS[partner].words} (|correlation| "
                f"{correlations.max():.3f} > {CORRELATION_LIMIT})")
    if estimate.at_bound:
        return f"the data do not determine it: the search ends on a bound ({estimate.value:.4g})"
    if estimate.determined != "well":
        return f"the data do not determine it well enough ({estimate.text()})"
    return None


def estimate_soil(data: TestBedData, wheel: Wheel = Wheel(), prior: Soil = Soil(),
                  parameters: Sequence[str] | None = None, *, noise: Mapping[str, float] | None = None,
                  bounds: Mapping[str, tuple[float, float]] | None = None, confidence: float = 0.95,
                  optional: bool = True) -> SoilEstimate:
    """The soil whose reference wheel best explains ``data`` (weighted least squares, see the module
    docstring).

    The plan's parameters are searched first; then each optional one in turn (a1, a0, λ, k_x,β,
    k_y,β) is added, searched from the previous values, and kept only if the data determine it
    beside the others (no |correlation| above 0.95, not on a bound, an interval within its
    resolution); otherwise it keeps the prior's value, and the reason is recorded. ``optional``
    False searches the plan's parameters only (the optional ones keep the prior's values, said so):
    each optional one costs a search of its own, several times the first one's evaluations.

    Args:
        data: steady-state single-wheel measurements.
        wheel: the wheel of the test bed.
        prior: the soil the search starts from; every parameter not estimated keeps its value.
        parameters: the Soil fields to estimate (names of :data:`SPECS`); None: the plan of
            :func:`plan_parameters` from the data's columns.
        noise: the standard deviation of each channel's measurement noise (``{"Fx_N": 2.0}``, the
            channel's unit); channels not given get theirs from the fit's residuals.
        bounds: search bounds [SI] replacing those of :data:`BOUNDS`.
        confidence: level of the intervals, in (0, 1).
        optional: search the plan's optional parameters in turn (else they keep the prior's values,
            each recorded as not searched).

    Raises ValueError with a message for data that cannot be fitted (a sinkage beyond the wheel's
    radius, too few measurements for the parameters, a parameter the columns cannot show).
    """
    started = time.perf_counter()
    if not (isinstance(confidence, float) and 0 < confidence < 1):
        raise ValueError(f"confidence={confidence!r}: expected a number in (0, 1)")
    plan = plan_parameters(data, prior, parameters, wheel)
    _check_fit_data(data, wheel, plan)
    scales, given = _noise_scales(data, noise)
    limits = _bounds(prior, bounds)
    problem = _Problem(data, wheel, prior, plan.estimated, scales)
    found = _search(problem, {}, limits, given, confidence)
    evaluations = problem.evaluations
    dropped: list[FixedParameter] = [FixedParameter(name, getattr(prior, name), NOT_SEARCHED)
                                     for name in plan.optional if not optional]
    for name in plan.optional if optional else ():
        trial = _Problem(data, wheel, prior, (*problem.names, name), problem.scales)
        attempt = _search(trial, dict(zip(problem.names, (float(v) for v in found[0]))), limits, given, confidence)
        evaluations += trial.evaluations
        reason = _rejection(trial, attempt[2], attempt[3], name)
        if reason is None:
            problem, found = trial, attempt
        else:
            dropped.append(FixedParameter(name, getattr(prior, name), reason))
    z, message, statistics, estimates = found
    fitted = problem.predict(z)
    residuals = {name: ChannelResiduals(name, data.channel(name), fitted.channel(name), problem.scales[name],
                                        name in given) for name in data.channels}
    return SoilEstimate(
        soil=problem.soil(z), prior=prior, wheel=wheel, data=data, parameters=estimates,
        fixed={f.name: f for f in (*plan.fixed, *dropped)}, correlation=statistics.correlation,
        covariance=statistics.covariance, residuals=residuals,
        identifiability=_identifiability(problem, statistics, estimates, plan, dropped, optional),
        bekker_modulus=_bekker(problem, z, statistics, confidence), confidence=confidence,
        evaluations=evaluations + 1, seconds=time.perf_counter() - started, message=message)


def _search(problem: _Problem, previous: Mapping[str, float], limits: Mapping[str, tuple[float, float]],
            given: set[str], confidence: float) -> tuple[NDArray[np.float64], str, _Statistics,
                                                          dict[str, ParameterEstimate]]:
    """One search of ``problem``'s parameters (from ``previous`` values where known, else the
    prior's), its noise scales estimated anew (up to twice), and its statistics."""
    names = problem.names
    z0, low, high = _start(problem.prior, names, limits)
    if previous:
        z0 = np.clip(np.array([previous.get(n, v) for n, v in zip(names, z0)]), low, high)
    z, message = _fit(problem, z0, low, high)
    for _ in range(2):
        if len(given) == len(problem.data.channels) or not _reestimate_noise(problem, z, given):
            break
        z, message = _fit(problem, z, low, high)
    statistics = _statistics(problem, z, low, high)
    return z, message, statistics, _estimates(problem, z, statistics, low, high, confidence)


def _bekker(problem: _Problem, z: NDArray[np.float64], statistics: _Statistics, confidence: float) -> ParameterEstimate:
    """k = k_c/b + k_φ and its interval (delta method on the logarithms of k_c and k_φ)."""
    soil, b = problem.soil(z), problem.wheel.b
    value = soil.bekker_modulus(b)
    gradient = np.zeros(len(problem.names))
    for name, part in (("kc", soil.kc / b), ("kphi", soil.kphi)):
        if name in problem.names:
            gradient[problem.names.index(name)] = part / value  # d log k / d log k_i
    searched = bool(gradient.any())
    covariance = np.nan_to_num(statistics.covariance)
    error = float(np.sqrt(gradient @ covariance @ gradient)) if searched else 0.0
    quantile = _t_quantile(0.5 + confidence / 2, statistics.dof)
    unseen = bool(np.any(statistics.unseen & (gradient != 0)))
    low, high = value * math.exp(-quantile * error), value * math.exp(quantile * error)
    if unseen and np.count_nonzero(gradient) == 1:
        low = high = math.nan
    determined = "well" if 2 * quantile * error <= _FACTOR_4 else "poorly"
    prior = problem.prior.bekker_modulus(b)
    return ParameterEstimate("bekker_modulus", value, low, high, error, prior,
                             determined if searched else "not searched", False)


def soil_toml(estimate: SoilEstimate, name: str = "estimated", title: str | None = None,
              source: str | None = None) -> str:
    """The estimated soil as a table of the soil library's TOML format (``--soil FILE`` reads it:
    every Soil field in SI, φ in rad with its degrees in a comment, X_c left out where it follows
    φ), with ``title``, ``source`` and a note per parameter: estimated with its interval, or kept
    at the prior's value and why. Values are written exactly (repr), so the file gives back
    ``estimate.soil``."""
    soil = estimate.soil
    derived = math.isclose(soil.xc, xc_from_phi(soil.phi), rel_tol=0, abs_tol=1e-12)
    lines = [f"# Soil estimated by rover-cosim from {estimate.data.source} ({estimate.data.rows} rows); "
             f"{100 * estimate.confidence:g} % intervals in the notes.", f"[{name}]",
             f"title = {_toml_string(title or f'Estimated from {estimate.data.source}')}",
             f"source = {_toml_string(source or 'rover-cosim estimate-soil')}"]
    for key, value in asdict(soil).items():
        if key == "xc" and derived:
            continue
        comment = f"  # {math.degrees(value):.6g} deg" if key in ("phi", "xc") else ""
        lines.append(f"{key} = {float(value)!r}{comment}")
    lines += ["", f"[{name}.notes]"]
    for key, e in estimate.parameters.items():
        lines.append(f"{key} = {_toml_string('estimated: ' + e.text())}")
    for key, f in estimate.fixed.items():
        lines.append(f"{key} = {_toml_string(f'the prior value {f.value:.6g}: {f.reason}')}")
    if derived:
        lines.append(f"xc = {_toml_string('45 deg - phi/2 of the estimated phi')}")
    return "\n".join(lines) + "\n"


def _toml_string(text: str) -> str:
    """A TOML basic string (quotes, backslashes and control characters escaped)."""
    escaped = text.replace("\\", "\\\\").replace('"', '\\"')
    escaped = "".join(c if ord(c) >= 0x20 and c != "\x7f" else f"\\u{ord(c):04x}" for c in escaped)
    return f'"{escaped}"'
