"""common.rows.csv_bytes: the trajectories' CSV written a row at a time, byte for byte what
pandas writes (tables it does not take go through pandas)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from rover_cosim.common.rows import csv_bytes, every


def _table(rng: np.random.Generator) -> pd.DataFrame:
    """Floats across 24 decades, both signs, a negative zero and infinities; awkward column names."""
    values = rng.normal(size=(200, 6)) * 10.0 ** rng.integers(-12, 12, size=(200, 6))
    values[3, 2], values[4, 1], values[5, 0] = -0.0, np.inf, -np.inf
    return pd.DataFrame(values, columns=["time", "a,b", 'say "x"', "Fx[1]", "slip", "ω"])


@pytest.mark.parametrize("float_format", ["%.8g", "%.10g", "%.4f", "%.6e"])
def test_csv_bytes_is_what_pandas_writes(float_format):
    table = _table(np.random.default_rng(34))
    assert csv_bytes(table, float_format) == table.to_csv(index=False, float_format=float_format).encode()
    thinned = every(table, 0.005, 0.001)  # the rows a run keeps: a fresh index
    assert csv_bytes(thinned, float_format) == thinned.to_csv(index=False, float_format=float_format).encode()


def test_tables_it_does_not_format_go_through_pandas():
    table = _table(np.random.default_rng(35))
    with_nan = table.copy()
    with_nan.iloc[7, 3] = np.nan  # pandas writes an empty field, not "nan"
    with_text = table.assign(phase=["a"] * len(table))
    with_integers = table.assign(step=np.arange(len(table)))
    shuffled = table.iloc[::-1]  # an index that is not 0..n-1
    for other in (with_nan, with_text, with_integers, shuffled, table.iloc[:0]):
        assert csv_bytes(other, "%.8g") == other.to_csv(index=False, float_format="%.8g").encode()
    assert b",," in csv_bytes(with_nan, "%.8g") and b"nan" not in csv_bytes(with_nan, "%.8g")
