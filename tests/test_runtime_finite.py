"""The runtime's finiteness check (fmubuild/runtime/finite.h), which turns a model's infinite or
NaN output or derivative into an error instead of a value handed to the host: whatever the
length and wherever the bad value sits, it answers as numpy's isfinite does, and the largest
finite values do not overflow it."""

from __future__ import annotations

import ctypes
from pathlib import Path

import numpy as np
import pytest
from c_harness import compiled

HERE = Path(__file__).parent


@pytest.fixture(scope="module")
def harness(tmp_path_factory: pytest.TempPathFactory) -> ctypes.CDLL:
    library = compiled(tmp_path_factory, "finite", HERE / "finite_harness.c")
    library.all_finite.argtypes = [ctypes.POINTER(ctypes.c_double), ctypes.c_int]
    library.all_finite.restype = ctypes.c_int
    return library


def _check(harness: ctypes.CDLL, values: np.ndarray) -> bool:
    array = np.ascontiguousarray(values, dtype=float)
    return bool(harness.all_finite(array.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), len(array)))


SPECIALS = (np.inf, -np.inf, np.nan, -np.nan)
FINITE = (0.0, -0.0, 5e-324, -1.0, 1.7976931348623157e308, -1.7976931348623157e308)


@pytest.mark.parametrize("length", [0, 1, 2, 3, 4, 5, 7, 8, 9, 2033])
def test_one_bad_value_anywhere_is_found_and_none_is_invented(harness, length):
    base = np.resize(np.array([1.7976931348623157e308, -1.7976931348623157e308, 3.5, -0.0]), length)
    assert _check(harness, base)  # the largest values, summed plainly, would overflow to inf
    for position in {0, length // 2, length - 1} if length else set():
        for special in SPECIALS:
            values = base.copy()
            values[position] = special
            assert not _check(harness, values), (length, position, special)
        for finite in FINITE:
            values = base.copy()
            values[position] = finite
            assert _check(harness, values)


def test_random_arrays_agree_with_numpy(harness):
    rng = np.random.default_rng(11)
    for _ in range(300):
        values = rng.standard_normal(int(rng.integers(0, 40))) * 10.0 ** rng.integers(-300, 300)
        mask = rng.random(values.size) < 0.05
        values[mask] = rng.choice(np.array([*SPECIALS, *FINITE]), int(mask.sum()))
        assert _check(harness, values) == bool(np.isfinite(values).all())
