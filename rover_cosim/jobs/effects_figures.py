"""The figure of the wheel effects (issue 48), as PNG bytes (the computation stays in ``effects``)."""

from __future__ import annotations

from typing import NamedTuple

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from rover_cosim.identification.figures import png_bytes
from rover_cosim.terramechanics.kinematics import FloatArray


class Trends(NamedTuple):
    """What the trends figure shows (``effects_figures.trends``)."""

    heights: FloatArray  #: grouser heights [m]
    count_at: float  #: the grouser count of the height sweep [1]
    pull_by_height: FloatArray  #: drawbar pull at 20 % slip [N] per height
    counts: FloatArray  #: grouser counts [1]
    height_at: float  #: the grouser height of the count sweep [m]
    pull_by_count: FloatArray  #: drawbar pull at 20 % slip [N] per count
    slips: FloatArray  #: slip ratios [1]
    sinkage_by_n_slip: dict[float, FloatArray]  #: sinkage [m] per slip, for each n_slip [1]
    title: str
    #: A source's measured sinkage at a slip: (slip [1], least and largest ratio to the static
    #: sinkage [1], the source in words), and the n_slip [1] range that gives it on the chosen soil.
    reported: tuple[float, float, float, str]
    n_slip_band: tuple[float, float]


def trends(data: Trends) -> bytes:
    """Drawbar pull at 20 % slip against grouser height and count; sinkage against slip per n_slip."""
    figure, axes = plt.subplots(1, 3, figsize=(13, 4.2))
    axes[0].plot(1e3 * data.heights, data.pull_by_height, "o-")
    axes[0].set(xlabel=f"grouser height [mm] ({data.count_at:g} grousers)",
                ylabel="drawbar pull Fx at 20 % slip [N]", title="grousers: height")
    axes[1].plot(data.counts, data.pull_by_count, "o-")
    axes[1].set(xlabel=f"number of grousers ({1e3 * data.height_at:g} mm high)",
                ylabel="drawbar pull Fx at 20 % slip [N]",
                title="grousers: count")
    for n_slip, sinkage in data.sinkage_by_n_slip.items():
        axes[2].plot(data.slips, sinkage / sinkage[0], label=f"n_slip = {n_slip:g}")
    slip, low, high, source = data.reported
    axes[2].errorbar([slip], [0.5 * (low + high)], yerr=[[0.5 * (high - low)]], fmt="none", ecolor="black",
                     capsize=6, lw=2, label=f"measured, {source}:\n{low:g}-{high:g}x at slip {slip:g}\n"
                                            f"(n_slip {data.n_slip_band[0]:.2g}-{data.n_slip_band[1]:.2g} here)")
    axes[2].set(xlabel="slip ratio [-]", ylabel="sinkage / static sinkage [-]",
                title="slip-sinkage: exponent n + n_slip |slip|")
    axes[2].legend(fontsize=8, loc="upper left")
    for axis in axes:
        axis.grid(alpha=0.3)
    figure.suptitle(data.title)
    return png_bytes(figure)
