"""The identification plan: which loads and torques the sweep runs, which of them the Fx fits take,
and where the model is validated, for the soil, wheel and rover at hand.

The paper's plan (loads 100-800 N, torques 5-80 N·m, fits to 40 N·m, validation at 275, 575,
875 N with a 5-40 N·m staircase) is made for its 0.355 m wheel under 424 N. A plan for another
choice keeps the paper's shape and scales it (:func:`plan_for`):

- loads: the paper's loads as multiples of its static wheel load (0.24 ... 1.89, validation at
  0.65, 1.36, 2.06) times the rover's own static load M g / N (g: the soil's gravity);
- torques: the paper's levels times the ratio of the wheel's resistance torque Tx at the rover's
  static load and 20 % slip to the paper's (the numpy reference wheel, Eqs. 1-13), so that the
  levels give the same slips on the new wheel and soil as the paper's on its own;
- then, per load, a check with the reference wheel that at least three levels up to the fits'
  largest torque settle with their slip in the fits' window (``fits.SLIP_FIT_RANGE``); where
  fewer do, the levels that settle at 5, 20 and 35 % slip under that load are added.

A choice that cannot be driven is refused before the sweep (:class:`NotDrivable`): a wheel that
sinks to its radius under the rover's static load, or one that cannot pull (Fx <= 0 at 30 %
slip). A plan can also be given as a TOML file (:func:`read_plan`, ``identify --plan``).
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np

from rover_cosim.common.paper import LOADS as PAPER_LOADS
from rover_cosim.common.paper import STATIC_WHEEL_LOAD
from rover_cosim.terramechanics import Soil, Wheel, wheel_state
from rover_cosim.terramechanics.library import Choice, choose

from .fits import FIT_TORQUE_MAX, SLIP_FIT_RANGE
from .sweep import PAPER_TORQUES
from .validate import VALIDATION_LOADS, VALIDATION_TORQUES

#: Slip [1] at which the torque scale of a wheel and soil is measured (the middle of the fits' range).
SCALE_SLIP = 0.2
#: Settled slips [1] whose torques are added at a load where too few levels fall in the window.
ADDED_SLIPS = (0.05, 0.2, 0.35)
#: Points a load needs in the window: a degree-2 fit in slip.
POINTS_NEEDED = 3


class NotDrivable(ValueError):
    """The soil, wheel and rover of a choice cannot make a drivable rover: the message says why."""


@dataclass(frozen=True)
class IdentificationPlan:
    """What ``identify`` runs and fits (SI): sweep ``loads`` [N] x ``torques`` [N·m]; the Fx fits take
    the settled points with torque <= ``fit_torque_max`` [N·m] and slip in ``slip_window`` [1]
    (the paper's (-0.1, 0.5), fixed); Table 1 validates at ``validation_loads`` [N] with a
    staircase of ``validation_torques`` [N·m]. ``basis`` says where the plan came from."""

    loads: tuple[float, ...] = PAPER_LOADS
    torques: tuple[float, ...] = PAPER_TORQUES
    fit_torque_max: float = FIT_TORQUE_MAX
    validation_loads: tuple[float, ...] = VALIDATION_LOADS
    validation_torques: tuple[float, ...] = VALIDATION_TORQUES
    slip_window: tuple[float, float] = SLIP_FIT_RANGE
    basis: str = "the paper's plan (Sec. 2.2.7, Table 1)"

    def __post_init__(self) -> None:
        for name in ("loads", "torques", "validation_loads", "validation_torques"):
            values = getattr(self, name)
            if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
                raise ValueError(f"plan {name} = {values!r}: expected a list of numbers")
            numbers = []
            for value in values:
                if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                    raise ValueError(f"plan {name} = {list(values)!r}: expected finite numbers")
                numbers.append(float(value))
            if not numbers or any(v <= 0 for v in numbers):
                unit = "N" if "loads" in name else "N·m"
                raise ValueError(f"plan {name} = {numbers!r}: expected at least one value, each > 0 {unit}")
            if len(set(numbers)) != len(numbers):
                raise ValueError(f"plan {name} = {numbers!r}: expected distinct values")
            object.__setattr__(self, name, tuple(numbers))
        if len(self.loads) < 2:
            raise ValueError(f"plan loads = {list(self.loads)!r}: expected at least two loads (the LUT interpolates "
                             "in 1/W)")
        if not (isinstance(self.fit_torque_max, (int, float)) and self.fit_torque_max > 0):
            raise ValueError(f"plan fit_torque_max = {self.fit_torque_max!r}: expected > 0 N·m")
        if tuple(self.slip_window) != SLIP_FIT_RANGE:
            raise ValueError(f"plan slip_window = {self.slip_window!r}: the fits' window is fixed at {SLIP_FIT_RANGE}")
        object.__setattr__(self, "fit_torque_max", float(self.fit_torque_max))
        object.__setattr__(self, "slip_window", tuple(self.slip_window))

    @property
    def is_paper(self) -> bool:
        """Whether this is the paper's plan, value for value."""
        paper = IdentificationPlan()
        return all(getattr(self, f.name) == getattr(paper, f.name) for f in fields(self) if f.name != "basis")

    def to_dict(self) -> dict[str, Any]:
        """The plan for a record (lists, SI)."""
        return {key: list(value) if isinstance(value, tuple) else value for key, value in asdict(self).items()}


def read_plan(path: Path) -> IdentificationPlan:
    """A plan from a TOML file: ``loads``, ``torques``, ``fit_torque_max``, ``validation_loads``,
    ``validation_torques`` (each optional: the paper's where left out). ValueError names what is wrong."""
    try:
        table = tomllib.loads(Path(path).read_text())
    except FileNotFoundError:
        raise ValueError(f"plan {path}: no such file") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError, IsADirectoryError, PermissionError) as error:
        raise ValueError(f"plan {path}: not a readable TOML file ({error})") from None
    known = {"loads", "torques", "fit_torque_max", "validation_loads", "validation_torques"}
    unknown = sorted(set(table) - known - {"title", "notes"})
    if unknown:
        raise ValueError(f"plan {path}: unknown key(s) {unknown}; expected {', '.join(sorted(known))}")
    values: dict[str, Any] = {key: (tuple(value) if isinstance(value, list) else value) for key, value in table.items()
                              if key in known}
    try:
        return IdentificationPlan(**values, basis=f"the plan file {path}")
    except (ValueError, TypeError) as error:
        raise ValueError(f"plan {path}: {error}") from None


def _significant(value: float, digits: int = 3) -> float:
    """``value`` rounded to ``digits`` significant digits (plan levels a person can read)."""
    if value == 0:
        return 0.0
    return float(f"{value:.{digits}g}")


def _is_paper(choice: Choice) -> bool:
    paper = choose()
    return choice.soil == paper.soil and choice.wheel == paper.wheel and choice.rover == paper.rover


def static_load(choice: Choice) -> float:
    """The rover's static wheel load on level ground [N]: M g / N, g the soil's gravity."""
    return choice.rover.static_wheel_load(choice.soil.gravity)


def _state(choice: Choice, load: float, slip: np.ndarray) -> Any:
    return wheel_state(np.full_like(slip, load), slip, choice.wheel, choice.soil)


def check_drivable(choice: Choice) -> None:
    """NotDrivable naming the soil, wheel, rover and load where the wheel sinks to its radius under
    the rover's static load, or cannot pull (Fx <= 0 at 30 % slip)."""
    from rover_cosim.terramechanics.library import soil_label

    load = static_load(choice)
    what = f"{soil_label(choice)}: the static wheel load {load:.1f} N (M g / N = {choice.rover.mass:g} kg x " \
           f"{choice.soil.gravity:g} m/s² / {choice.rover.wheels})"
    try:
        state = _state(choice, load, np.array([0.0, 0.3]))
    except ValueError as error:
        raise NotDrivable(f"{what}: the wheel (r = {choice.wheel.r:g} m, b = {choice.wheel.b:g} m) cannot carry it: "
                          f"it sinks to its radius ({error}); a wider or larger wheel, a lighter rover or more "
                          "wheels") from None
    if not float(state.Fx[1]) > 0:
        raise NotDrivable(f"{what}: the wheel cannot pull: Fx = {float(state.Fx[1]):.3g} N at 30 % slip (the "
                          "soil's thrust does not overcome its compaction resistance); the rover would not move")


def _carried(choice: Choice, loads: list[float]) -> list[float]:
    """The loads the wheel carries without sinking to its radius."""
    kept = []
    for load in loads:
        try:
            _state(choice, load, np.array([0.0]))
            kept.append(load)
        except ValueError:
            continue
    return kept


def _settled_slip_range(choice: Choice, load: float) -> tuple[float, float]:
    """Tx [N·m] at the ends of the fits' slip window under ``load``: the torques that settle inside it."""
    state = _state(choice, load, np.array(SLIP_FIT_RANGE, dtype=float))
    return float(state.Tx[0]), float(state.Tx[1])


def _torque_levels(choice: Choice, scale: float, loads: list[float]) -> tuple[set[float], float, list[float]]:
    """The paper's torque levels times ``scale`` and its fits' largest torque likewise, with the
    levels added where a load of ``loads`` [N] has fewer than POINTS_NEEDED in the window;
    (torques [N·m], fits' largest torque [N·m], the added ones)."""
    torques = {_significant(t * scale) for t in PAPER_TORQUES}
    fit_max = _significant(FIT_TORQUE_MAX * scale)
    added = []
    for w in loads:
        low, high = _settled_slip_range(choice, w)
        inside = [t for t in torques if low <= t <= min(high, fit_max)]
        if len(inside) < POINTS_NEEDED:
            extra = _state(choice, w, np.array(ADDED_SLIPS)).Tx
            for t in extra:
                if t > 0:
                    torques.add(_significant(float(t)))
                    added.append(_significant(float(t)))
            fit_max = max(fit_max, max(_significant(float(t)) for t in extra))
    return torques, fit_max, added


def torques_for(soil: Soil, wheel: Wheel, loads: tuple[float, ...]) -> tuple[tuple[float, ...], float]:
    """Torque levels [N·m] and the fits' largest torque [N·m] for a sweep of ``wheel`` on ``soil``
    at ``loads`` [N] (a re-identification on an estimated soil): the paper's for the paper's wheel,
    else the paper's scaled by the wheel's Tx at the loads' middle (as :func:`plan_for` scales)."""
    paper = choose()
    if wheel == paper.wheel:
        return PAPER_TORQUES, FIT_TORQUE_MAX
    choice = dataclasses.replace(paper, soil=soil, wheel=wheel, wheel_name="the rover's")
    middle = float(np.median(loads))
    scale = float(_state(choice, middle, np.array([SCALE_SLIP])).Tx[0]) / float(
        _state(paper, STATIC_WHEEL_LOAD, np.array([SCALE_SLIP])).Tx[0])
    torques, fit_max, _ = _torque_levels(choice, scale, list(loads))
    return tuple(sorted(torques)), fit_max


def plan_for(choice: Choice) -> IdentificationPlan:
    """The paper's plan for the paper's soil, wheel and rover; for any other choice the paper's
    plan scaled to it (module docstring). NotDrivable before any sweep where the choice cannot
    be driven."""
    if _is_paper(choice):
        return IdentificationPlan()
    check_drivable(choice)
    load = static_load(choice)
    paper = choose()
    scale = float(_state(choice, load, np.array([SCALE_SLIP])).Tx[0]) / float(
        _state(paper, STATIC_WHEEL_LOAD, np.array([SCALE_SLIP])).Tx[0])
    factor = load / STATIC_WHEEL_LOAD
    loads = _carried(choice, sorted({_significant(w * factor) for w in PAPER_LOADS}))
    validation = _carried(choice, [_significant(w * factor) for w in VALIDATION_LOADS])
    if len(loads) < 2 or not validation:
        raise NotDrivable(f"{choice.wheel_name} wheel on {choice.soil_name}: it carries only {loads} of the plan's "
                          f"loads around the static load {load:.1f} N")
    torques, fit_max, added = _torque_levels(choice, scale, loads)
    basis = (f"the paper's plan scaled to {choice.rover_name} rover on {choice.soil_name} with the {choice.wheel_name} "
             f"wheel{' (' + ', '.join(choice.overrides) + ')' if choice.overrides else ''}: loads x {factor:.4g} "
             f"(static wheel load {load:.1f} N against the paper's "
             f"{STATIC_WHEEL_LOAD:.1f} N), torques x {scale:.4g} (Tx at {SCALE_SLIP:g} slip against the paper's)"
             + (f"; added {sorted(set(added))} N·m where a load had fewer than {POINTS_NEEDED} levels in the window"
                if added else ""))
    return IdentificationPlan(
        loads=tuple(loads), torques=tuple(sorted(torques)), fit_torque_max=fit_max, validation_loads=tuple(validation),
        validation_torques=tuple(_significant(t * scale) for t in VALIDATION_TORQUES), basis=basis)
