"""Your own soil, end to end: Fig. 3, identification and the closed loop on a soil TOML file.

The soil (examples/grc1.toml unless --soil names another file) is read through the soil library,
then the pipeline's jobs run on it from Python, each into its own folder under --out:

1. fig3/            Fx against slip for several loads on the numpy reference wheel;
2. identification/  the paper's Sec. 3 on SingleWheel.fmu: torque-step sweep, Fx(W, slip)
                    fits, validation (Table 1), the lateral model; model.json;
3. simulation/      the paper's Sec. 4: the closed-loop rover (20 s) on Rover.fmu and on
                    RoverBody + 6 Wheel, with the controller built on that model.

    python examples/own_soil.py --out grc1_results            # the paper's sweep: 648 runs of 0.1 s
    python examples/own_soil.py --out grc1_results --quick    # a small sweep: 60 runs of 20 ms

--quick (or ROVER_COSIM_EXAMPLE_QUICK=1) computes Fig. 3 on a coarse grid and identifies from a
small sweep (fewer loads, torques, slip angles; 20 ms runs): enough for a controller, not the
paper's tables. Needs the FMUs of `make fmus` in --fmu-dir.
"""

from __future__ import annotations

import argparse
import math
import os
from pathlib import Path

from rover_cosim.identification.sweep import SweepPlan
from rover_cosim.jobs.fig3 import slip_grid, write_fig3
from rover_cosim.jobs.identify import run_identification
from rover_cosim.jobs.simulate import run_simulation
from rover_cosim.terramechanics.library import choose

NAME = "own_soil"
HERE = Path(__file__).resolve().parent
#: The small sweep of --quick. The lateral fits need at least four loads (one form is cubic in
#: the load), and its figures show the 10 N·m and 10 deg runs, so those are kept.
QUICK_PLAN = SweepPlan(loads=(200.0, 450.0, 700.0), torques=(5.0, 15.0, 30.0, 40.0), stop_time=0.02)
QUICK_LATERAL_PLAN = SweepPlan(loads=(200.0, 400.0, 600.0, 800.0), torques=(5.0, 10.0, 30.0),
                               slip_angles_deg=(0.0, 5.0, 10.0, 25.0), stop_time=0.02, sample_time=1e-3)


def output_folder(parser: argparse.ArgumentParser, folder: Path) -> Path:
    """``folder``, made if missing; one that holds files this example did not write is refused."""
    marker = folder / f".{NAME}"
    if folder.is_dir() and any(folder.iterdir()) and not marker.exists():
        parser.error(f"{folder} holds files this example did not write: choose a new or empty folder with --out")
    folder.mkdir(parents=True, exist_ok=True)
    marker.touch()
    return folder


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=Path("example_output") / NAME, help="output folder")
    parser.add_argument("--soil", type=Path, default=HERE / "grc1.toml", help="the soil's TOML file")
    parser.add_argument("--fmu-dir", type=Path, default=Path("fmus"), help="where the FMUs are (make fmus)")
    parser.add_argument("--workers", type=int, default=None, help="processes for the sweep (default: all cores)")
    parser.add_argument("--quick", action="store_true", default=bool(os.environ.get("ROVER_COSIM_EXAMPLE_QUICK")),
                        help="a coarse Fig. 3 and a small sweep; also ROVER_COSIM_EXAMPLE_QUICK=1")
    args = parser.parse_args()
    needed = ("SingleWheel.fmu", "Rover.fmu", "RoverBody.fmu", "Wheel.fmu")
    missing = [name for name in needed if not (args.fmu_dir / name).is_file()]
    if missing:
        parser.error(f"{', '.join(missing)} not in {args.fmu_dir}: build them with `make fmus`")
    out = output_folder(parser, args.out)

    # The soil library reads the file: unknown keys and impossible values are errors naming them.
    choice = choose(str(args.soil))
    print(f"soil {choice.soil_name} ({choice.soil_entry.get('title')}), wheel {choice.wheel_name}")
    print(f"  c = {choice.soil.c:g} Pa, phi = {math.degrees(choice.soil.phi):g} deg, kc = {choice.soil.kc:g}, "
          f"kphi = {choice.soil.kphi:g}, n = {choice.soil.n:g}, kx = {choice.soil.kx:g} m")

    # 1. Fig. 3 on the numpy reference wheel.
    loads = (200.0, 500.0, 800.0) if args.quick else (100.0, 200.0, 300.0, 400.0, 500.0, 600.0, 700.0, 800.0)
    figure = write_fig3(out / "fig3", loads, slip_grid(0.1 if args.quick else 0.01), choice=choice)
    print(f"Fig. 3: {', '.join(str(p) for p in figure)}")

    # 2. Identification on SingleWheel.fmu, the soil given to the FMU as parameters (no rebuild).
    identified = run_identification(args.fmu_dir / "SingleWheel.fmu", out / "identification",
                                    plan=QUICK_PLAN if args.quick else None,
                                    lateral_plan=QUICK_LATERAL_PLAN if args.quick else None,
                                    workers=args.workers, choice=choice)
    print(f"identification: {len(identified.files)} files in {out / 'identification'}; Fit of Fx (Eq. 15): "
          + ", ".join(f"{w:g} N {f:.1f} %" for w, f in zip(identified.fit["load_N"], identified.fit["fit_percent"])))

    # 3. The closed loop on both plants with the model just identified (same soil: not refused).
    simulated = run_simulation(args.fmu_dir, out / "identification" / "model.json", out / "simulation", choice)
    for plant, table in simulated.rms.items():
        checks = simulated.record["checks"][plant]
        print(f"closed loop ({plant}): RMS(Fx - Fx_des) per limb "
              + " / ".join(f"{v:.2f}" for v in table["rms_N"]) + f" N; final speed {checks['final_v_m_s']:.3f} m/s")
    print(f"wrote {len(figure) + len(identified.files) + len(simulated.files)} files under {out} "
          "(fig3/, identification/, simulation/)")


if __name__ == "__main__":
    main()
