"""Input checks for the vectorized physics functions: clear errors naming the bad value."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .kinematics import FloatArray


def checked_array(name: str, value: ArrayLike, low: float, high: float, unit: str,
                  low_open: bool = False) -> FloatArray:
    """``value`` as a float array, or ValueError naming the first element outside the range.

    The accepted range is [low, high], or (low, high] when ``low_open``; NaN and infinities
    are never accepted.
    """
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{name}={value!r}: expected real numbers") from error
    ok = (array > low) if low_open else (array >= low)
    ok &= (array <= high) & np.isfinite(array)
    if not ok.all():
        index = tuple(int(i) for i in np.argwhere(~ok)[0]) if array.ndim else ()
        bad = array[index] if array.ndim else array.item()
        where = f"{name}[{', '.join(map(str, index))}]" if array.ndim else name
        unit = f" {unit}" if unit else ""
        if np.isinf(high):
            accepted = f"{'>' if low_open else '>='} {low!r}{unit}"
        else:
            accepted = f"in {'(' if low_open else '['}{low!r}, {high!r}]{unit}"
        raise ValueError(f"{where}={float(bad)!r}{unit}: expected a finite value {accepted}")
    return array


def check_nodes(nodes: int) -> None:
    """ValueError unless ``nodes`` is a quadrature node count: an integer in [2, 10000]."""
    if isinstance(nodes, bool) or not isinstance(nodes, (int, np.integer)) or not 2 <= nodes <= 10_000:
        raise ValueError(f"nodes={nodes!r}: expected an integer in [2, 10000]")
