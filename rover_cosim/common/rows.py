"""Rows to keep: a recorded table thinned to a row every recording interval, and written as CSV."""

from __future__ import annotations

import csv
import io
import math
import os
import re
from collections.abc import Iterable
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pandas is imported by whoever hands a table (the command line checks an interval without it)
    import pandas as pd


def steps_between_rows(interval: float, step: float) -> int:
    """Steps of ``step`` [s] between two kept rows; ValueError unless ``interval`` [s] is a whole
    number (>= 1) of them."""
    count = interval / step if isinstance(interval, (int, float)) and 0 < interval < math.inf else 0.0
    if not count < 2**53:  # beyond any run, and beyond what a whole number of steps can be told apart
        raise ValueError(f"record interval {interval!r} s: expected a whole number of steps of {step} s "
                         "within a run's length")
    if round(count) < 1 or abs(count - round(count)) > 1e-9 * max(1.0, count):
        raise ValueError(f"record interval {interval!r} s: expected a whole number of steps of {step} s")
    return round(count)


def every(table: pd.DataFrame, interval: float, step: float) -> pd.DataFrame:
    """The rows of ``table`` (one per ``step`` [s]) every ``interval`` [s], and the last one."""
    k = steps_between_rows(interval, step)
    kept = sorted(set(range(0, len(table), k)) | {len(table) - 1})
    return table.iloc[kept].reset_index(drop=True)


def csv_bytes(table: pd.DataFrame, float_format: str) -> bytes:
    """``table.to_csv(index=False, float_format=float_format)``, byte for byte, formatted a row at a
    time where every column is float64 and no value is NaN (one % per row: pandas formats value by
    value, ~10x slower on the trajectories' ~80 columns); other tables through pandas."""
    import pandas as pd

    values = table.to_numpy()
    if (table.empty or not all(dtype == np.float64 for dtype in table.dtypes) or np.isnan(values).any()
            or not isinstance(table.index, pd.RangeIndex)):
        return table.to_csv(index=False, float_format=float_format).encode()
    header = io.StringIO()
    csv.writer(header, lineterminator=os.linesep).writerow([str(c) for c in table.columns])
    row = ",".join([float_format] * table.shape[1]) + os.linesep
    return (header.getvalue() + "".join(row % tuple(line) for line in values.tolist())).encode()


def indices(columns: Iterable[str], stem: str) -> range:
    """The numbers 1..N of the columns ``<stem>[i]`` (recorded data) or ``<stem>_<i>`` (a trajectory
    table) among ``columns``: the wheels a run had."""
    columns = list(columns)
    pattern = re.compile(rf"{re.escape(stem)}(?:\[(\d+)\]|_(\d+))")
    found = [int(match.group(1) or match.group(2)) for match in map(pattern.fullmatch, columns) if match]
    if not found:
        raise ValueError(f"no columns {stem}[i] or {stem}_i among {list(columns)[:8]}...")
    return range(1, max(found) + 1)
