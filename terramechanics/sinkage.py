"""Static sinkage of the wheel: the h that solves Fz(h, κ) = W, and the wheel state there.

The paper says the sinkage is "decided by the optimization"; here it is the root of
log Fz(h) - log W in log h, found by a secant iteration safeguarded by bisection inside a
bracket (0, r]. Fz grows roughly like h^((2n+1)/2) (Bekker), so in log-log coordinates the
function is nearly linear and the secant converges in a handful of steps from the Bekker
flat-plate estimate of the sinkage.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .checks import check_nodes, checked_array
from .forces import DEFAULT_NODES, ContactForces, contact_integrals
from .kinematics import FloatArray, entry_angle, exit_angle, max_stress_angle
from .parameters import Soil, Wheel

#: Smallest sinkage the iteration looks at, as a fraction of the wheel radius [-].
MIN_SINKAGE_RATIO = 1e-12
MAX_ITERATIONS = 100
#: Batches at least this large start from a coarse-grid solution (see _initial_log_sinkage).
GRID_BATCH_SIZE = 2000
GRID_SHAPE = (24, 21)


@dataclass(frozen=True)
class WheelState:
    """A wheel in equilibrium with its load; all arrays have the broadcast input shape."""

    load: FloatArray  #: vertical load W [N]
    slip: FloatArray  #: slip ratio κ [-]
    sinkage: FloatArray  #: sinkage h [m] below the undisturbed surface (the rut's depth included)
    Fx: FloatArray  #: longitudinal force [N], Eq. (12)
    Fz: FloatArray  #: vertical force [N], Eq. (11), equal to the load
    Tx: FloatArray  #: resistance torque [N·m], Eq. (13)
    Fy: FloatArray  #: lateral force [N] at the slip angle (0 at slip_angle = 0)
    Fy_sidewall: FloatArray  #: the sidewall (bulldozing) part of Fy [N]
    slip_angle: FloatArray  #: slip angle β [rad]
    entry_angle: FloatArray  #: θf [rad], Eq. (1)
    exit_angle: FloatArray  #: θr [rad], Eq. (2), negative
    max_stress_angle: FloatArray  #: θm [rad], Eq. (3)
    rut_depth: FloatArray  #: depth of the rut the wheel rolls in [m] (0: virgin soil); the angles are its patch's

    #: The table columns of each field, with their units (to_frame).
    COLUMNS = {"load": "load_N", "slip": "slip", "sinkage": "sinkage_m", "Fx": "Fx_N", "Fz": "Fz_N", "Tx": "Tx_Nm",
               "Fy": "Fy_N", "Fy_sidewall": "Fy_sidewall_N", "slip_angle": "slip_angle_rad",
               "entry_angle": "entry_angle_rad", "exit_angle": "exit_angle_rad",
               "max_stress_angle": "max_stress_angle_rad", "rut_depth": "rut_depth_m"}

    def to_frame(self) -> Any:
        """The state as a pandas DataFrame, one row per element (flattened), the columns named with
        their units (load_N, slip, sinkage_m, Fx_N, ...)."""
        import pandas as pd

        shape = np.broadcast_shapes(*(np.shape(getattr(self, name)) for name in self.COLUMNS))
        return pd.DataFrame({column: np.broadcast_to(np.asarray(getattr(self, name), dtype=float), shape).ravel()
                             for name, column in self.COLUMNS.items()})


def bekker_sinkage(load: ArrayLike, wheel: Wheel, soil: Soil) -> FloatArray:
    """Bekker's rigid-wheel estimate h = [3W / ((3 - n) b k √(2r))]^(2/(2n+1)) [m], no slip.

    Only a starting point for the iteration; the (3 - n) factor needs n < 3, so n is capped at
    2.9 here.
    """
    k = soil.bekker_modulus(wheel.b)
    base = 3.0 * np.asarray(load, dtype=float) / ((3.0 - min(soil.n, 2.9)) * wheel.b * k * math.sqrt(2 * wheel.r))
    return base ** (2.0 / (2.0 * soil.n + 1.0))


def _grid_axis(low: float, high: float, count: int, pad: float, limits: tuple[float, float]) -> FloatArray:
    """``count`` points from ``low`` to ``high``, widened by ``pad`` (within ``limits``) if the
    range is too narrow for an interpolation axis."""
    if high - low < pad:
        low, high = max(low - pad, limits[0]), min(high + pad, limits[1])
    return np.linspace(low, high, count)


def _initial_guess(load: FloatArray, slip: FloatArray, wheel: Wheel, soil: Soil,
                   nodes: int, lateral: bool = False) -> tuple[FloatArray, FloatArray]:
    """Starting log h and slope d log Fz / d log h for the iteration.

    Small batches start from Bekker's estimate and slope n + 1/2. Large batches first solve a
    coarse (log W, κ) grid spanning the batch and interpolate its log h and slope linearly;
    the grid costs a few hundred solves and saves over one evaluation per element (4.4 -> 3.1
    on 100 000 random states). If the grid cannot be solved (a load in the batch is more than
    the wheel can carry), Bekker's start is used and the iteration reports the load.
    """
    log_bekker = np.log(bekker_sinkage(load, wheel, soil))
    bekker_slope = np.full(load.shape, soil.n + 0.5)
    if load.size < GRID_BATCH_SIZE or lateral:
        return log_bekker, bekker_slope
    log_w = _grid_axis(np.log(load.min()), np.log(load.max()), GRID_SHAPE[0], 0.01, (-np.inf, np.inf))
    kappa = _grid_axis(slip.min(), slip.max(), GRID_SHAPE[1], 0.01, (-1.0, 1.0))
    grid_w, grid_k = (a.ravel() for a in np.meshgrid(np.exp(log_w), kappa, indexing="ij"))
    try:
        h_grid, _ = solve_sinkage(grid_w, grid_k, wheel, soil, 1e-10, nodes)
    except ValueError:
        return log_bekker, bekker_slope
    log_h = np.log(h_grid).reshape(GRID_SHAPE)
    correction = log_h - np.log(bekker_sinkage(grid_w, wheel, soil)).reshape(GRID_SHAPE)
    slope = 1.0 / np.asarray(np.gradient(log_h, log_w, axis=0))
    # Imported here: SciPy takes ~0.4 s to import, and small batches (every command's) never need it.
    from scipy.interpolate import RegularGridInterpolator

    points = np.column_stack([np.log(load), slip])

    def interpolate(values: FloatArray) -> FloatArray:
        return RegularGridInterpolator((log_w, kappa), values, bounds_error=False, fill_value=None)(points)

    return log_bekker + interpolate(correction), interpolate(slope)


def solve_sinkage(load: FloatArray, slip: FloatArray, wheel: Wheel, soil: Soil,
                  rtol: float, nodes: int, slip_angle: FloatArray | None = None,
                  rut: FloatArray | None = None) -> tuple[FloatArray, ContactForces]:
    """Sinkage h [m] with |Fz(h, κ)/W - 1| <= rtol, and the contact forces there, for checked
    1-D arrays ``load`` and ``slip``; ``rut`` (None: no rut) the rut's depth [m], h then below its floor.

    Iterates on x = log h with the residual f = log Fz - log W: the first step is Newton's with
    an estimated slope d log Fz / d log h (see _initial_guess), later steps are secant steps;
    a step that leaves the bracket (or a residual that is undefined because Fz <= 0, possible for a
    skidding wheel that has barely sunk) falls back to bisection. Only unconverged elements
    are evaluated again.
    """
    log_load = np.log(load)
    lower = np.full(load.shape, math.log(MIN_SINKAGE_RATIO * wheel.r))
    upper = np.full(load.shape, math.log(wheel.r))
    lateral = slip_angle is not None and bool(np.any(slip_angle != 0.0))
    beta = slip_angle if lateral else None
    rutted = rut is not None and bool(np.any(rut != 0.0))
    ruts = rut if rutted else None
    x, slope = _initial_guess(load, slip, wheel, soil, nodes, lateral or rutted)
    x = np.clip(x, lower, upper)
    x_prev = np.full(load.shape, np.nan)
    f_prev = np.full(load.shape, np.nan)
    out = ContactForces(*(np.empty(load.shape) for _ in ContactForces._fields))
    tol = math.log1p(rtol)
    active = np.arange(load.size)
    for _ in range(MAX_ITERATIONS):
        if active.size == 0:
            break
        xa = x[active]
        forces = contact_integrals(np.exp(xa), slip[active], wheel, soil, nodes,
                                   None if beta is None else beta[active], None if ruts is None else ruts[active])
        with np.errstate(divide="ignore", invalid="ignore"):
            log_fz = np.where(forces.Fz > 0, np.log(np.maximum(forces.Fz, 1e-300)), -np.inf)
        fa = log_fz - log_load[active]
        done = np.abs(fa) <= tol
        for target, value in zip(out, forces):
            target[active[done]] = value[done]
        lower[active] = np.where(fa < 0, xa, lower[active])
        upper[active] = np.where(fa > 0, xa, upper[active])
        xp, fp = x_prev[active], f_prev[active]
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.where(np.isnan(xp), xa - fa / slope[active], xa - fa * (xa - xp) / (fa - fp))
        lo, hi = lower[active], upper[active]
        step = np.where(~np.isfinite(step) | (step <= lo) | (step >= hi), 0.5 * (lo + hi), step)
        x_prev[active], f_prev[active] = xa, fa
        x[active] = np.where(done, xa, step)
        active = active[~done]
    if active.size:
        _raise_unsolved(load[active], slip[active], wheel, soil, nodes, None if beta is None else beta[active],
                        None if ruts is None else ruts[active])
    return np.exp(x), out


def _raise_unsolved(load: FloatArray, slip: FloatArray, wheel: Wheel, soil: Soil, nodes: int,
                    beta: FloatArray | None, rut: FloatArray | None = None) -> None:
    capacity = contact_integrals(np.full(load.shape, wheel.r), slip, wheel, soil, nodes, beta, rut).Fz
    too_heavy = load > capacity
    if too_heavy.any():
        i = int(np.argmax(too_heavy))
        raise ValueError(
            f"load={float(load[i])!r} N at slip={float(slip[i])!r}: the wheel (r={wheel.r} m) cannot "
            f"carry it with a sinkage below its radius; the most it carries at that slip is "
            f"{capacity[i]:.6g} N")
    raise RuntimeError(f"sinkage iteration did not converge for load={float(load[0])!r} N, "
                       f"slip={float(slip[0])!r}")


def wheel_state(
    load: ArrayLike, slip: ArrayLike, wheel: Wheel = Wheel(), soil: Soil = Soil(), *,
    rtol: float = 1e-10, nodes: int = DEFAULT_NODES, slip_angle: ArrayLike = 0.0, rut_depth: ArrayLike = 0.0,
) -> WheelState:
    """The wheel in equilibrium: sinkage h solving Fz(h, κ) = W, and the forces there.

    Args:
        load: vertical wheel load W [N], each > 0 (and at most what the wheel carries at h = r).
        slip: slip ratio κ [-], each in [-1, 1]; broadcasts against ``load``.
        wheel: wheel parameters (paper Table 2 by default).
        soil: soil parameters (paper Table 2 by default).
        rtol: relative tolerance on Fz = W [-].
        nodes: Gauss-Legendre nodes per piece of the contact patch.
        slip_angle: slip angle β [rad], each in (-π/2, π/2); broadcasts. At 0 every output is
            the paper's, bit for bit, and Fy = 0.
        rut_depth: depth z_r [m] >= 0 of the rut a previous wheel left where this one rolls
            (multi-pass, :mod:`terramechanics.multipass`); broadcasts. The wheel sinks below the
            rut's floor into soil that already carried the pressure of depth z_r; ``sinkage`` is
            the total below the undisturbed surface. At 0 every output is the virgin soil's, bit
            for bit.
    """
    if not (isinstance(rtol, (int, float)) and 1e-15 <= rtol <= 1e-2):
        raise ValueError(f"rtol={rtol!r}: expected a number in [1e-15, 1e-2]")
    check_nodes(nodes)
    w = checked_array("load", load, 0.0, math.inf, "N", low_open=True)
    kappa = checked_array("slip", slip, -1.0, 1.0, "")
    beta = checked_array("slip_angle", slip_angle, -math.pi / 2, math.pi / 2, "rad", low_open=True)
    if np.any(np.abs(beta) >= math.pi / 2):
        raise ValueError(f"slip_angle={float(np.max(np.abs(beta)))!r} rad: expected |slip_angle| < pi/2")
    rut = checked_array("rut_depth", rut_depth, 0.0, wheel.r, "m")
    w, kappa, beta, rut = np.broadcast_arrays(w, kappa, beta, rut)
    shape = w.shape
    w, kappa, beta, rut = w.ravel().copy(), kappa.ravel().copy(), beta.ravel().copy(), rut.ravel().copy()

    h, forces = solve_sinkage(w, kappa, wheel, soil, rtol, nodes, beta, rut)
    theta_f = entry_angle(h, wheel)

    def shaped(a: FloatArray) -> FloatArray:
        return a.reshape(shape)

    return WheelState(
        load=shaped(w), slip=shaped(kappa), sinkage=shaped(h + rut),
        Fx=shaped(forces.Fx), Fz=shaped(forces.Fz), Tx=shaped(forces.Tx),
        Fy=shaped(forces.Fy), Fy_sidewall=shaped(forces.Fy_sidewall), slip_angle=shaped(beta),
        entry_angle=shaped(theta_f), exit_angle=shaped(exit_angle(h, wheel, soil)),
        max_stress_angle=shaped(max_stress_angle(theta_f, kappa, soil)), rut_depth=shaped(rut),
    )
