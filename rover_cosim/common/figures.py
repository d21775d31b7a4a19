"""How figures leave the process: PNG bytes (what every job's figure function returns), and the
same figure in the other formats and at the resolution a user asks for (``rover-cosim
--figures png,pdf,svg --dpi 200 ...``).

A figure function renders with :func:`render`; the bytes it returns are PNG and carry the other
formats along (:class:`Rendered`); :func:`rover_cosim.common.outputs.write_all` writes those
beside the PNG (``fig.png`` -> ``fig.pdf``, ``fig.svg``), all or none with the rest.
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from typing import Any

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
