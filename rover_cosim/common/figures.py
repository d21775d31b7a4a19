"""How figures leave the process: PNG bytes (what every job's figure function returns), and the
same figure in the other formats and at the resolution a user asks for (``rover-cosim
--figures png,pdf,svg --dpi 200 ...``).

A figure function renders with :func:`render`; the bytes it returns are PNG and carry the other
formats along (:class:`Rendered`); :func:`rover_cosim.common.outputs.write_all` writes those
beside the PNG (``fig.png`` -> ``fig.pdf``, ``fig.svg``), all or none with the rest.
"""

from __future__ import annotations

import io
import math
from collections.abc import Callable, Hashable, Mapping
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np

Key = TypeVar("Key", bound=Hashable)

#: The formats a figure may be written in besides PNG (matplotlib's backends for them).
FORMATS = ("png", "pdf", "svg")


@dataclass
class FigureSettings:
    """The formats every figure is written in (PNG always) and the PNG resolution (None: each
    figure's own, 100-150 dpi)."""

    formats: tuple[str, ...] = ("png",)
    dpi: float | None = None


#: The settings of this process (the command line sets them).
SETTINGS = FigureSettings()


def configure(formats: tuple[str, ...] = ("png",), dpi: float | None = None) -> None:
    """Set the figure formats and PNG dpi of this process; ValueError naming a bad one."""
    unknown = [f for f in formats if f not in FORMATS]
    if unknown:
        raise ValueError(f"figure formats {unknown}: expected some of {', '.join(FORMATS)}")
    if dpi is not None and not 20 <= dpi <= 1200:
        raise ValueError(f"dpi {dpi!r}: expected 20 to 1200")
    SETTINGS.formats = tuple(dict.fromkeys(("png", *formats)))
    SETTINGS.dpi = dpi


class Rendered(bytes):
    """A figure's PNG bytes with its other renderings (suffix -> bytes) attached."""

    others: dict[str, bytes]


def render(fig: Any, dpi: float) -> Rendered:
    """``fig`` (a matplotlib Figure) as PNG at the settings' dpi (else ``dpi``), with the other
    formats of the settings attached."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=SETTINGS.dpi or dpi)
    rendered = Rendered(buffer.getvalue())
    rendered.others = {}
    for kind in SETTINGS.formats:
        if kind != "png":
            other = io.BytesIO()
            fig.savefig(other, format=kind)
            rendered.others[f".{kind}"] = other.getvalue()
    return rendered


#: Points per plotted line past which :func:`thinned` thins it (a 1 ms run of 20 s has 20,001; an
#: axis of a figure is a few hundred pixels wide).
LINE_POINTS = 4000


def thinned(x: Any, y: Any, points: int = LINE_POINTS) -> tuple[np.ndarray, np.ndarray]:
    """A line of many samples (``x`` increasing) as at most ~``points`` of them that draw the same:
    in each of ``points``/2 consecutive bins its smallest and its largest ``y`` (in their order),
    and the first and last samples, so that no peak is lost. Shorter lines come back whole."""
    x, y = np.asarray(x), np.asarray(y)
    n = len(x)
    if n <= points:
        return x, y
    width = -(-n // max(1, points // 2))
    whole = n // width * width
    bins = y[:whole].reshape(-1, width)
    low, high = bins.argmin(axis=1), bins.argmax(axis=1)
    starts = np.arange(bins.shape[0]) * width
    index = np.empty(2 * len(starts), dtype=np.int64)
    index[0::2] = starts + np.minimum(low, high)
    index[1::2] = starts + np.maximum(low, high)
    index = np.unique(np.concatenate(([0], index, np.arange(whole, n), [n - 1])))
    return x[index], y[index]


def drawn(figures: Mapping[Key, Callable[[], bytes]], workers: int | None = None) -> dict[Key, bytes]:
    """Each figure function's bytes by its key, drawn side by side in ``workers`` processes
    (default: the cores) where processes can be forked (the functions and what they draw are the
    parent's, not sent), else one after the other here. The same bytes either way: a figure
    function is pure (so is any other function of bytes given with them: a job's CSVs, made in the
    figures' gaps)."""
    import multiprocessing

    from .parallel import cores, parallel_map

    keys = list(figures)
    workers = min(workers or cores(), len(keys))
    if workers <= 1 or "fork" not in multiprocessing.get_all_start_methods():
        return {key: figures[key]() for key in keys}

    def draw(index: int) -> tuple[int, bytes]:
        return index, figures[keys[index]]()

    def lost(arguments: tuple[Any, ...], reason: str) -> Any:
        raise RuntimeError(f"figure {keys[arguments[0]]}: {reason}")

    done = dict(parallel_map(draw, [(k,) for k in range(len(keys))], workers, lost=lost, timeout=math.inf))
    return {key: done[k] for k, key in enumerate(keys)}
