"""The identified lateral-force model Fy(W, beta, slip) (the paper's future work, after Ishigami
et al. 2007): the sweep's settled points at slip angles 0-30 deg, a model linear in its
coefficients, and its candidate forms.

Form: Fy = sum_i sum_k c_ik(W) phi_i(beta) slip^k, with phi_i odd in beta (so Fy(-beta) = -Fy(beta)
and Fy(0) = 0 by construction), k = 0..slip_degree and each c_ik a polynomial of degree
load_degree in W. The coefficients are found by one linear least-squares fit over all settled
points of all loads (per-load fits are shown in the coefficient figure); the points enter under
the longitudinal fits' rules (the wheel still rolls, torque <= FIT_TORQUE_MAX, slip in
SLIP_FIT_RANGE). Fy at a slip angle saturates within a few degrees (the lateral shear is
mobilised within a few k_y of sideways travel), which an odd polynomial in beta cannot follow;
saturating bases can:

- ``rational``: phi_i = beta / (|beta| + beta_i) (first-order rational, saturating at 1);
- ``exponential``: phi_i = sign(beta) (1 - exp(-|beta| / beta_i));
- ``polynomial``: phi_i = beta^(2i-1) (the plain odd polynomial, for comparison).

The scales beta_i span the sweep's angles. :data:`FORMS` lists what is tried; the job reports
each form's Fits and uses :data:`RECOMMENDED_FORM`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd

from .fits import FIT_TORQUE_MAX, SLIP_FIT_RANGE, settled, step_table
from .sweep import Case

#: deg; the lateral sweep's slip angles (0-30 deg as Ishigami's experiments; 7.5 and 12.5 deg,
#: the validation angles, lie between them).
LATERAL_SLIP_ANGLES_DEG = (0.0, 2.5, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0)
#: s; the lateral runs are recorded at 1 ms (only their settled values enter the fits).
LATERAL_SAMPLE_TIME = 1e-3


@dataclass(frozen=True)
class LateralForm:
    """One candidate form of Fy(W, beta, slip) (see the module docstring)."""

    name: str
    basis: str                        # "rational", "exponential" or "polynomial"
    scales_deg: tuple[float, ...]     # beta_i [deg] (rational, exponential); one entry per term
    slip_degree: int
    load_degree: int

    def __post_init__(self) -> None:
        if self.basis not in ("rational", "exponential", "polynomial"):
            raise ValueError(f"basis = {self.basis!r}: expected 'rational', 'exponential' or 'polynomial'")
        if not self.scales_deg or any(not (b > 0) for b in self.scales_deg):
            raise ValueError(f"scales_deg = {self.scales_deg!r}: expected one or more scales > 0 deg")
        if self.slip_degree < 0 or self.load_degree < 0:
            raise ValueError(f"slip_degree = {self.slip_degree}, load_degree = {self.load_degree}: expected >= 0")

    def angle_basis(self, beta: np.ndarray) -> list[np.ndarray]:
        """phi_i(beta) for beta [rad], each odd in beta."""
        beta = np.asarray(beta, float)
        if self.basis == "polynomial":
            return [beta ** (2 * i + 1) for i in range(len(self.scales_deg))]
        scales = np.radians(self.scales_deg)
        if self.basis == "rational":
            return [beta / (np.abs(beta) + s) for s in scales]
        return [np.sign(beta) * -np.expm1(-np.abs(beta) / s) for s in scales]

    def angle_basis_slope(self, beta: np.ndarray) -> list[np.ndarray]:
        """d phi_i / d beta [1/rad]."""
        beta = np.asarray(beta, float)
        if self.basis == "polynomial":
            return [(2 * i + 1) * beta ** (2 * i) for i in range(len(self.scales_deg))]
        scales = np.radians(self.scales_deg)
        if self.basis == "rational":
            return [s / (np.abs(beta) + s) ** 2 for s in scales]
        return [np.exp(-np.abs(beta) / s) / s for s in scales]

    def angle_terms(self, beta: float) -> tuple[list[float], list[float]]:
        """(phi_i(beta), d phi_i / d beta [1/rad]) at one slip angle [rad] in plain floats, in the
        order of operations the path controller's C twin (``path_controller.c``) repeats; the
        same values as angle_basis and angle_basis_slope up to round-off."""
        scales = self.scales_rad
        if self.basis == "polynomial":
            return ([beta ** (2 * i + 1) for i in range(len(scales))],
                    [(2 * i + 1) * beta ** (2 * i) for i in range(len(scales))])
        magnitude = abs(beta)
        if self.basis == "rational":
            return ([beta / (magnitude + s) for s in scales],
                    [s / ((magnitude + s) * (magnitude + s)) for s in scales])
        sign = 1.0 if beta > 0 else -1.0 if beta < 0 else beta  # np.sign: 0 and NaN kept
        return ([sign * -math.expm1(-magnitude / s) for s in scales], [math.exp(-magnitude / s) / s for s in scales])

    @property
    def scales_rad(self) -> list[float]:
        """beta_i [rad]."""
        return np.radians(self.scales_deg).tolist()

    def columns(self, load: np.ndarray, beta: np.ndarray, slip: np.ndarray, *, with_load: bool = True) -> np.ndarray:
        """The regression matrix: phi_i(beta) slip^k W^j, ordered [i, k, j] (j only with_load)."""
        load, slip = np.asarray(load, float), np.asarray(slip, float)
        powers = range(self.load_degree + 1) if with_load else range(1)
        return np.column_stack([phi * slip**k * load**j for phi in self.angle_basis(beta)
                                for k in range(self.slip_degree + 1) for j in powers])

    def shape(self) -> tuple[int, int, int]:
        return len(self.scales_deg), self.slip_degree + 1, self.load_degree + 1


#: The candidate forms, the recommended one first.
FORMS = (
    LateralForm("rational3_s1_W2", "rational", (2.5, 7.0, 20.0), 1, 2),
    LateralForm("rational3_s1_W3", "rational", (2.5, 7.0, 20.0), 1, 3),
    LateralForm("rational3_s2_W2", "rational", (2.5, 7.0, 20.0), 2, 2),
    LateralForm("exponential3_s1_W2", "exponential", (3.0, 10.0, 30.0), 1, 2),
    LateralForm("rational2_s1_W2", "rational", (4.0, 15.0), 1, 2),
    LateralForm("polynomial135_s1_W2", "polynomial", (1.0, 1.0, 1.0), 1, 2),
)
RECOMMENDED_FORM = FORMS[0]
#: W [N] is scaled by this inside the fit (conditioning of the W^j columns); coefficients are
#: reported for W in N.
_LOAD_SCALE = 1000.0


@dataclass
class LateralModel:
    """Fy(W, beta, slip) = sum c[i, k, j] phi_i(beta) slip^k W^j [N], W in N, beta in rad."""

    form: LateralForm
    coefficients: np.ndarray   # shape form.shape()

    def fy(self, load: float | np.ndarray, slip_angle: float | np.ndarray, slip: float | np.ndarray) -> np.ndarray:
        """The lateral force [N] at load W [N] (> 0), slip angle [rad] and slip ratio."""
        load, beta, slip = np.broadcast_arrays(np.asarray(load, float), np.asarray(slip_angle, float),
                                               np.asarray(slip, float))
        if np.any(~(load > 0)):
            raise ValueError(f"load = {load!r} N: expected > 0")
        design = self.form.columns(load.ravel(), beta.ravel(), slip.ravel())
        return (design @ self.coefficients.ravel()).reshape(load.shape)

    def angle_coefficients(self, load: np.ndarray, slip: np.ndarray) -> np.ndarray:
        """a_i(W, slip) = sum_k c_ik(W) slip^k, shape (n, terms): Fy = sum_i a_i phi_i(beta)."""
        load, slip = np.atleast_1d(np.asarray(load, float)), np.atleast_1d(np.asarray(slip, float))
        terms, slips, loads = self.form.shape()
        slip_powers = slip[:, None] ** np.arange(slips)         # (n, k)
        load_powers = load[:, None] ** np.arange(loads)         # (n, j)
        return np.einsum("ikj,nk,nj->ni", self.coefficients, slip_powers, load_powers)

    def fy_and_slope(self, coefficients: np.ndarray, slip_angle: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Fy [N] and dFy/dbeta [N/rad] at slip angles [rad] for angle_coefficients rows."""
        phi = np.array(self.form.angle_basis(slip_angle))        # (terms, n)
        slope = np.array(self.form.angle_basis_slope(slip_angle))
        return (coefficients * phi.T).sum(axis=1), (coefficients * slope.T).sum(axis=1)

    def angle_coefficients_at(self, load: float, slip: float) -> list[float]:
        """angle_coefficients at one load [N] and slip in plain floats (c[i, k, j] slip^k W^j
        summed over k, then j, from 0), as the path controller's C twin sums them."""
        table = np.asarray(self.coefficients, float).tolist()
        terms, slips, loads = self.form.shape()
        slip_powers = [slip ** k for k in range(slips)]
        load_powers = [load ** j for j in range(loads)]
        result = []
        for i in range(terms):
            total = 0.0
            for k in range(slips):
                for j in range(loads):
                    total += table[i][k][j] * slip_powers[k] * load_powers[j]
            result.append(total)
        return result

    def fy_and_slope_at(self, coefficients: list[float], slip_angle: float) -> tuple[float, float]:
        """fy_and_slope at one slip angle [rad] in plain floats: (Fy [N], dFy/dbeta [N/rad])."""
        phi, slope = self.form.angle_terms(slip_angle)
        fy = dfy = 0.0
        for a, p, q in zip(coefficients, phi, slope):
            fy += a * p
            dfy += a * q
        return fy, dfy

    def coefficient_at(self, load: float | np.ndarray, term: int, slip_power: int) -> np.ndarray:
        """c_ik(W) [N]: the polynomial in W of one term."""
        return np.polynomial.polynomial.polyval(np.asarray(load, float), self.coefficients[term, slip_power])

    def to_dict(self) -> dict[str, object]:
        return {"form": asdict(self.form), "coefficients_N": self.coefficients.tolist(),
                "meaning": "Fy = sum_ikj c[i][k][j] phi_i(beta) slip^k W^j [N], W in N, beta in rad; "
                           "phi_i: rational beta/(|beta| + beta_i), exponential sign(beta)(1 - exp(-|beta|/beta_i)), "
                           "polynomial beta^(2i+1); beta_i = scales_deg in rad"}

    @staticmethod
    def from_dict(data: dict) -> LateralModel:
        form = dict(data["form"])
        form["scales_deg"] = tuple(form["scales_deg"])
        return LateralModel(LateralForm(**form), np.array(data["coefficients_N"], float))


def lateral_table(runs: dict[Case, pd.DataFrame]) -> pd.DataFrame:
    """One row per run: load_N, torque_N_m, slip_angle_deg, settled slip, Fx_N, Fy_N and whether
    the wheel still rolls (fits.step_table's rule)."""
    rows = []
    for angle in sorted({c.slip_angle_deg for c in runs}):
        at_angle = {(c.load, c.torque): run for c, run in runs.items() if c.slip_angle_deg == angle}
        steps = step_table(at_angle).set_index(["load_N", "torque_N_m"])
        for (load, torque), run in sorted(at_angle.items()):
            rows.append({"load_N": load, "torque_N_m": torque, "slip_angle_deg": angle,
                         "slip": settled(run, "slip"), "Fx_N": settled(run, "Fx"), "Fy_N": settled(run, "Fy"),
                         "rolling": bool(steps.loc[(load, torque), "rolling"])})
    return pd.DataFrame(rows)


def fit_points(table: pd.DataFrame, torque_max: float = FIT_TORQUE_MAX) -> pd.DataFrame:
    """The rows that enter the fits: rolling, torque <= ``torque_max`` [N·m] (the plan's; the
    paper's FIT_TORQUE_MAX), slip in SLIP_FIT_RANGE."""
    keep = (table["rolling"].astype(bool) & (table["torque_N_m"] <= torque_max)
            & (table["slip"] >= SLIP_FIT_RANGE[0]) & (table["slip"] <= SLIP_FIT_RANGE[1]))
    return table[keep]


def identify_lateral(table: pd.DataFrame, form: LateralForm = RECOMMENDED_FORM,
                     torque_max: float = FIT_TORQUE_MAX) -> LateralModel:
    """The model of ``form`` by linear least squares over the settled points of all loads (torques
    up to ``torque_max`` [N·m])."""
    points = fit_points(table, torque_max)
    if points["load_N"].nunique() < form.load_degree + 1:
        raise ValueError(f"{points['load_N'].nunique()} loads with usable lateral runs, need "
                         f"{form.load_degree + 1} for coefficients of degree {form.load_degree} in W")
    scaled = points["load_N"].to_numpy() / _LOAD_SCALE
    beta = np.radians(points["slip_angle_deg"].to_numpy())
    design = form.columns(scaled, beta, points["slip"].to_numpy())
    solution, *_ = np.linalg.lstsq(design, points["Fy_N"].to_numpy(), rcond=None)
    unscale = _LOAD_SCALE ** -np.arange(form.load_degree + 1)
    return LateralModel(form, solution.reshape(form.shape()) * unscale)


def per_load_coefficients(table: pd.DataFrame, form: LateralForm = RECOMMENDED_FORM,
                          torque_max: float = FIT_TORQUE_MAX) -> pd.DataFrame:
    """Per load, the c_ik of ``form`` fitted to that load's points alone: load_N, c{i}{k} [N]."""
    rows = []
    for load, part in fit_points(table, torque_max).groupby("load_N"):
        design = form.columns(part["load_N"].to_numpy(), np.radians(part["slip_angle_deg"].to_numpy()),
                              part["slip"].to_numpy(), with_load=False)
        solution, *_ = np.linalg.lstsq(design, part["Fy_N"].to_numpy(), rcond=None)
        terms, slips, _ = form.shape()
        rows.append({"load_N": load, **{f"c{i}{k}": float(solution[i * slips + k])
                                        for i in range(terms) for k in range(slips)}})
    return pd.DataFrame(rows)


def training_rms(model: LateralModel, table: pd.DataFrame, torque_max: float = FIT_TORQUE_MAX) -> float:
    """RMS [N] of the model against the fitted settled points."""
    points = fit_points(table, torque_max)
    predicted = model.fy(points["load_N"].to_numpy(), np.radians(points["slip_angle_deg"].to_numpy()),
                         points["slip"].to_numpy())
    return float(math.sqrt(np.mean((predicted - points["Fy_N"].to_numpy()) ** 2)))


def ishigami_trends(table: pd.DataFrame, torque_max: float = FIT_TORQUE_MAX) -> pd.DataFrame:
    """The side-force trends Ishigami et al. (2007) report from their single-wheel experiments,
    measured on the sweep's fitted points: trend, holds (bool), measured (what was compared)."""
    points = fit_points(table, torque_max).assign(magnitude=lambda t: t["Fy_N"].abs())
    rises, levels, falls, grows = [], [], [], []
    for _, part in points.groupby(["load_N", "torque_N_m"]):
        ordered = part.sort_values("slip_angle_deg")["magnitude"].to_numpy()
        rises.append(bool(np.all(np.diff(ordered) > 0)))
        by_angle = part.set_index("slip_angle_deg")["magnitude"]
        if {0.0, 10.0, 20.0, 30.0} <= set(by_angle.index):
            levels.append((by_angle[30.0] - by_angle[20.0]) / (by_angle[10.0] - by_angle[0.0]))
    for _, part in points[points["slip_angle_deg"] > 0].groupby(["load_N", "slip_angle_deg"]):
        ordered = part.sort_values("slip")
        falls.append(bool(ordered["magnitude"].iloc[-1] < ordered["magnitude"].iloc[0]))
    for _, part in points[points["slip_angle_deg"] > 0].groupby(["slip_angle_deg", "torque_N_m"]):
        grows.append(bool(np.all(np.diff(part.sort_values("load_N")["magnitude"].to_numpy()) > 0)))
    rows = [("|Fy| rises with the slip angle", all(rises), f"{sum(rises)}/{len(rises)} (load, torque) series"),
            ("|Fy| levels off towards 30 deg: the rise 20->30 deg is below a third of 0->10 deg",
             bool(levels) and max(levels) < 1 / 3, f"largest ratio {max(levels, default=float('nan')):.3f}"),
            ("|Fy| falls as the slip grows", all(falls), f"{sum(falls)}/{len(falls)} (load, angle) series"),
            ("|Fy| grows with the load", all(grows), f"{sum(grows)}/{len(grows)} (angle, torque) series")]
    return pd.DataFrame(rows, columns=["trend", "holds", "measured"])
