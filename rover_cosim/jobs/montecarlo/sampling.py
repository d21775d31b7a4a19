"""Seeded samples of a study: sample 0 is the nominal soil, samples 1 ... runs-1 are drawn.

Every parameter is drawn through a Gaussian copula: standard-normal scores z (numpy Generator,
PCG64, seeded with the study's seed) are correlated as z L^T with L the Cholesky factor of the
study's correlation matrix, turned into probabilities u = Phi(z), and each u into its parameter's
value by the inverse CDF of its (truncated) marginal. Truncation by the inverse CDF needs no
rejection, so the sample count and the random stream do not depend on the bounds; and the
scores fill row by row, so a study with more runs keeps the first samples of a smaller one (the
cache keeps serving them).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.special import ndtr, ndtri

from .study import Distribution, Study

#: Least probability mass a truncation may keep: bounds further out in the tail than this are refused.
LEAST_MASS = 1e-9


def scores(study: Study, count: int) -> np.ndarray:
    """(count, d) correlated standard-normal scores of the study's seed."""
    generator = np.random.Generator(np.random.PCG64(study.seed))
    z = generator.standard_normal((count, len(study.parameters)))
    return z @ np.linalg.cholesky(study.correlation).T


def quantile(distribution: Distribution, u: np.ndarray) -> np.ndarray:
    """The values at probabilities ``u`` in (0, 1) of the distribution, truncated to its bounds."""
    d = distribution
    if d.kind == "uniform":
        return d.a + u * (d.b - d.a)
    low, high = d.bounds()
    if d.kind == "normal":
        centre, low_score, high_score = d.a, low, high
    else:  # in ln x; a lower bound at 0 is no bound
        centre = float(np.log(d.a))
        low_score = float(np.log(low)) if low > 0 else -np.inf
        high_score = float(np.log(high)) if np.isfinite(high) else np.inf
    p_low, p_high = float(ndtr((low_score - centre) / d.b)), float(ndtr((high_score - centre) / d.b))
    if p_high - p_low < LEAST_MASS:
        raise ValueError(f"parameter {d.name}: bounds [{low!r}, {high!r}] keep a probability of "
                         f"{p_high - p_low:.3g} of the {d.kind} distribution: expected bounds around its centre")
    z = centre + d.b * ndtri(p_low + u * (p_high - p_low))
    values = z if d.kind == "normal" else np.exp(z)
    return np.clip(values, low, high)


def draw(study: Study, count: int) -> np.ndarray:
    """(count, d) parameter values of ``count`` random samples (no nominal), columns in study order."""
    u = ndtr(scores(study, count))
    columns = [quantile(p, u[:, j]) for j, p in enumerate(study.parameters)]
    return np.column_stack(columns) if count else np.empty((0, len(study.parameters)))


def sample_table(study: Study, nominal: dict[str, float]) -> pd.DataFrame:
    """sample (0 ... runs-1), nominal (True for sample 0) and one column per parameter; sample 0
    holds ``nominal``'s values (the soil the model was identified on), the others are drawn."""
    missing = [n for n in study.names if n not in nominal]
    if missing:
        raise ValueError(f"nominal values of {', '.join(missing)} missing")
    values = np.vstack([[nominal[n] for n in study.names], draw(study, study.runs - 1)])
    table = pd.DataFrame(values, columns=study.names)
    table.insert(0, "nominal", np.arange(study.runs) == 0)
    table.insert(0, "sample", np.arange(study.runs))
    return table
