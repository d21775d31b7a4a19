"""Drawbar pull against slip from Python, with the numpy reference wheel.

For several wheel loads the reference wheel solves its sinkage so that the soil carries the load
(Fz = W) at every slip ratio, and gives the drawbar pull Fx (thrust minus compaction resistance)
there. No FMU is involved.

    python examples/drawbar_pull.py --out drawbar --soil dry_sand --loads 100,300,500,800

Writes <out>/drawbar_pull_vs_slip.png (the figure) and <out>/drawbar_pull_vs_slip.csv (the numbers).
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from rover_cosim.terramechanics import wheel_state
from rover_cosim.terramechanics.library import choose

NAME = "drawbar_pull_vs_slip"


def output_folder(parser: argparse.ArgumentParser, folder: Path) -> Path:
    """``folder``, made if missing; one that holds files this example did not write is refused."""
    marker = folder / ".drawbar_pull"
    if folder.is_dir() and any(folder.iterdir()) and not marker.exists():
        parser.error(f"{folder} holds files this example did not write: choose a new or empty folder with --out")
    folder.mkdir(parents=True, exist_ok=True)
    marker.touch()
    return folder


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=Path("example_output") / "drawbar_pull", help="output folder")
    parser.add_argument("--soil", default="paper", help="a shipped soil (rover-cosim soils) or a TOML file")
    parser.add_argument("--wheel", default="paper", help="a shipped wheel or a TOML file")
    parser.add_argument("--loads", default="100,300,500,800", help="wheel loads W [N], comma-separated")
    parser.add_argument("--slips", type=int, default=91, help="number of slip ratios from 0 to 0.9")
    parser.add_argument("--quick", action="store_true", default=bool(os.environ.get("ROVER_COSIM_EXAMPLE_QUICK")),
                        help="10 slip ratios; also ROVER_COSIM_EXAMPLE_QUICK=1")
    args = parser.parse_args()
    loads = np.array([float(w) for w in args.loads.split(",")])        # N
    slips = np.linspace(0.0, 0.9, 10 if args.quick else args.slips)     # -
    out = output_folder(parser, args.out)

    choice = choose(args.soil, args.wheel)
    # One call for every (load, slip) pair: the arrays broadcast to a loads x slips grid.
    state = wheel_state(loads[:, None], slips[None, :], choice.wheel, choice.soil)

    figure = Figure(figsize=(7.0, 4.5), dpi=120)
    axes = figure.add_subplot()
    for i, load in enumerate(loads):
        axes.plot(slips, state.Fx[i], label=f"W = {load:g} N")
    axes.axhline(0.0, color="0.5", lw=0.8)
    axes.set_xlabel("Slip ratio κ [-]")
    axes.set_ylabel("Drawbar pull $F_x$ [N]")
    axes.set_title(f"Drawbar pull against slip: soil {choice.soil_name}, wheel {choice.wheel_name}")
    axes.grid(alpha=0.3)
    axes.legend(title="Wheel load")
    figure.tight_layout()
    png, csv = out / f"{NAME}.png", out / f"{NAME}.csv"
    figure.savefig(png)
    state.to_frame()[["load_N", "slip", "sinkage_m", "Fx_N", "Fz_N", "Tx_Nm"]].to_csv(csv, index=False,
                                                                                     float_format="%.10g")

    for i, load in enumerate(loads):
        print(f"W = {load:5g} N: drawbar pull {state.Fx[i, 0]:7.2f} N at slip 0, {state.Fx[i, -1]:7.2f} N at slip "
              f"{slips[-1]:g} (sinkage {1000 * state.sinkage[i, 0]:.1f} to {1000 * state.sinkage[i, -1]:.1f} mm)")
    print(f"wrote {png} and {csv}")


if __name__ == "__main__":
    main()
