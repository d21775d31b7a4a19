"""Rows to keep: a recorded table thinned to a row every recording interval."""

from __future__ import annotations

import math

import pandas as pd


def steps_between_rows(interval: float, step: float) -> int:
    """Steps of ``step`` [s] between two kept rows; ValueError unless ``interval`` [s] is a whole
    number (>= 1) of them."""
    count = interval / step if isinstance(interval, (int, float)) and 0 < interval < math.inf else 0.0
    if round(count) < 1 or abs(count - round(count)) > 1e-9 * max(1.0, count):
        raise ValueError(f"record interval {interval!r} s: expected a whole number of steps of {step} s")
    return round(count)


def every(table: pd.DataFrame, interval: float, step: float) -> pd.DataFrame:
    """The rows of ``table`` (one per ``step`` [s]) every ``interval`` [s], and the last one."""
    k = steps_between_rows(interval, step)
    kept = sorted(set(range(0, len(table), k)) | {len(table) - 1})
    return table.iloc[kept].reset_index(drop=True)
