"""Which uncertain parameter matters most: rank correlations of each output with each parameter (pure).

Rank correlations (so any monotonic effect counts, whatever its shape or units):
  spearman   Spearman's rank correlation of the output with the parameter alone;
  prcc       the partial rank correlation coefficient: the correlation of the output's ranks
             and the parameter's ranks after the linear effect of every other parameter's ranks
             is taken out of both (least squares), with its p-value (t test, n - 2 - (d - 1)
             degrees of freedom). The ranking is by |prcc|.
Why these and not Sobol indices (SALib): rank correlations need no special sampling design and
work with the study's plain Monte Carlo samples of any size, with correlated inputs (the study's
copula) and with the samples that failed left out; Sobol indices need Saltelli's design of
N (2d + 2) runs and independent inputs, and an extra dependency. What rank correlations miss:
non-monotonic effects and interactions (a scatter plot per parameter, figures.py, shows them).
The identified controller is exact at the nominal soil, so an output may worsen whichever way a
parameter departs from it (a V shape, invisible to both measures): a third measure, the Spearman
correlation of the output with the parameter's distance from its nominal value, catches that
(sensitivity's ``distance_spearman``); the ranking takes the larger of the two. An output that is
NaN (e.g. 0.98 m/s never reached) ranks after every finite value: never is the slowest.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.special import stdtr  # Student's t distribution; scipy.stats would be a second of imports

#: Outputs ranked, with their labels and units (the straight scenario's).
OUTPUTS = {"rms_Fx_max_N": "largest RMS(Fx - Fx_des) [N]", "time_to_98_s": "time to 0.98 m/s [s]",
           "steady_v_error_m_s": "steady velocity error [m/s]", "position_lag_m": "position lag [m]",
           "max_slip": "max slip [-]"}


def _ranks(values: np.ndarray) -> np.ndarray:
    """Ranks 1..n, ties sharing their mean rank, NaN ranked after every finite value (as
    scipy.stats.rankdata's average ranks, which are exact in floating point)."""
    return pd.Series(np.where(np.isnan(values), np.inf, values)).rank(method="average").to_numpy(float)


def _two_sided_p(t: float, freedom: int) -> float:
    """The two-sided p-value of Student's t statistic ``t`` with ``freedom`` degrees of freedom:
    2 P(T > |t|) (scipy.stats.t.sf(|t|, freedom) is stdtr(freedom, -|t|))."""
    return float(2 * stdtr(freedom, -abs(t)))


def _residual(target: np.ndarray, others: np.ndarray) -> np.ndarray:
    design = np.column_stack([np.ones(len(target)), others])
    coefficients, *_ = np.linalg.lstsq(design, target, rcond=None)
    return target - design @ coefficients


def _correlation(a: np.ndarray, b: np.ndarray) -> float:
    if np.std(a) < 1e-12 * max(1.0, np.abs(a).max()) or np.std(b) < 1e-12 * max(1.0, np.abs(b).max()):
        return float("nan")
    return float(np.corrcoef(a, b)[0, 1])


def prcc(inputs: np.ndarray, output: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(PRCC, p-value) of each column of ``inputs`` (n, d) with ``output`` (n,); NaN where the
    sample is too small (n <= d + 1) or a column does not vary."""
    n, d = inputs.shape
    coefficients, p_values = np.full(d, np.nan), np.full(d, np.nan)
    freedom = n - 2 - (d - 1)
    if freedom < 1:
        return coefficients, p_values
    ranks, ranked_output = np.column_stack([_ranks(inputs[:, j]) for j in range(d)]), _ranks(output)
    for j in range(d):
        others = np.delete(ranks, j, axis=1)
        r = _correlation(_residual(ranks[:, j], others), _residual(ranked_output, others))
        if np.isfinite(r):
            coefficients[j] = r
            t = r * np.sqrt(freedom / max(1.0 - r * r, 1e-300))
            p_values[j] = _two_sided_p(t, freedom)
    return coefficients, p_values


def distances(runs: pd.DataFrame, nominal: dict[str, float], logarithmic: set[str]) -> pd.DataFrame:
    """Each parameter's distance from its nominal value: |x - x0|, or |ln x - ln x0| for the
    parameters in ``logarithmic`` (log-normal ones, whose spread is a factor)."""
    table = {}
    for name, centre in nominal.items():
        values = runs[name].to_numpy(float)
        table[name] = np.abs(np.log(values / centre)) if name in logarithmic else np.abs(values - centre)
    return pd.DataFrame(table, index=runs.index)


def _spearman(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """Spearman's rho of ``a`` and ``b`` (NaN in ``b`` ranked last) with its p-value (t test)."""
    n = len(a)
    rho = _correlation(_ranks(a), _ranks(b)) if n > 2 else float("nan")
    if not np.isfinite(rho):
        return float("nan"), float("nan")
    t = rho * np.sqrt((n - 2) / max(1.0 - rho * rho, 1e-300))
    return rho, _two_sided_p(t, n - 2)


def sensitivity(runs: pd.DataFrame, parameters: list[str], outputs: dict[str, str] = OUTPUTS,
                nominal: dict[str, float] | None = None, logarithmic: frozenset[str] | set[str] = frozenset(),
                ) -> pd.DataFrame:
    """output, parameter, spearman, prcc, p_value, distance_spearman, distance_p_value, strongest,
    rank, n from the completed runs (one row per run, the parameters' and outputs' columns).

    distance_spearman: Spearman's rho of the output with the parameter's distance from ``nominal``
    (``distances``): a controller identified at the nominal soil may degrade whichever way the soil
    departs from it, a V-shaped effect that rank correlations with the value itself miss. The rank
    (1: most influential; empty without either measure) orders by the larger of |prcc| and
    |distance_spearman|; ``strongest`` says which it was ("monotonic" or "distance from nominal")."""
    rows = []
    inputs = runs[parameters].to_numpy(float)
    away = distances(runs, {p: nominal[p] for p in parameters}, set(logarithmic)).to_numpy(float) \
        if nominal is not None else np.full_like(inputs, np.nan)
    for output in (o for o in outputs if o in runs.columns):
        values = runs[output].to_numpy(float)
        coefficients, p_values = prcc(inputs, values)
        distance = [_spearman(away[:, j], values) for j in range(len(parameters))]
        strength = np.fmax(np.abs(coefficients), np.abs([d[0] for d in distance]))
        order = np.argsort(-np.nan_to_num(strength, nan=-1.0), kind="stable")
        rank = np.empty(len(parameters))
        rank[order] = np.arange(1, len(parameters) + 1)
        rank[np.isnan(strength)] = np.nan   # no ranking without a measure
        for j, name in enumerate(parameters):
            by_distance = bool(np.nan_to_num(abs(distance[j][0]), nan=-1) > np.nan_to_num(abs(coefficients[j]), nan=-1))
            rows.append({"output": output, "parameter": name, "spearman": _spearman(inputs[:, j], values)[0],
                         "prcc": coefficients[j], "p_value": p_values[j], "distance_spearman": distance[j][0],
                         "distance_p_value": distance[j][1],
                         "strongest": "" if np.isnan(strength[j]) else
                         ("distance from nominal" if by_distance else "monotonic"),
                         "rank": rank[j], "n": len(runs)})
    table = pd.DataFrame(rows, columns=["output", "parameter", "spearman", "prcc", "p_value", "distance_spearman",
                                        "distance_p_value", "strongest", "rank", "n"])
    table["rank"] = table["rank"].astype("Int64")
    return table
