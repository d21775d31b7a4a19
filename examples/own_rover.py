"""Your own rover, end to end: identification planned for its wheel and static load, then the
closed loop on its own number of wheels, monolithic and co-simulated.

The rover (examples/two_axle.toml unless --rover names another file or a shipped rover) is read
through the rover library with its wheel, on --soil (default lunar_nominal), then:

1. the identification plan for it (loads around its static wheel load M g / N, torques from its
   wheel's resistance torque on the soil; refused with the reason if it cannot be driven);
2. identification/  the sweep on SingleWheel.fmu by that plan, fits, Table 1, model.json;
3. simulation/      the paper's straight closed loop on Rover.fmu and RoverBody + N Wheel built
                    for its number of wheels (into --fmu-dir/wheels<N>/ on first use).

    python examples/own_rover.py --out two_axle            # the plan's whole sweep
    python examples/own_rover.py --out two_axle --quick    # every other load, 20 ms runs

Needs the FMUs of `make fmus` in --fmu-dir, and a C compiler for the rover FMUs of another wheel count.
"""

from __future__ import annotations

import argparse
import os
from dataclasses import replace
from pathlib import Path

from rover_cosim.identification.plan import NotDrivable, plan_for
from rover_cosim.identification.sweep import SweepPlan
from rover_cosim.jobs.identify import run_identification
from rover_cosim.jobs.simulate import run_simulation
from rover_cosim.terramechanics.library import choose

NAME = "own_rover"
HERE = Path(__file__).resolve().parent


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
    parser.add_argument("--rover", default=str(HERE / "two_axle.toml"), help="a rover file or a shipped rover")
    parser.add_argument("--soil", default="lunar_nominal", help="a soil file or a shipped soil")
    parser.add_argument("--fmu-dir", type=Path, default=Path("fmus"), help="where the FMUs are (make fmus)")
    parser.add_argument("--workers", type=int, default=None, help="processes for the sweep (default: all cores)")
    parser.add_argument("--quick", action="store_true", default=bool(os.environ.get("ROVER_COSIM_EXAMPLE_QUICK")),
                        help="every other load of the plan, 20 ms runs; also ROVER_COSIM_EXAMPLE_QUICK=1")
    args = parser.parse_args()
    missing = [n for n in ("SingleWheel.fmu", "Wheel.fmu") if not (args.fmu_dir / n).is_file()]
    if missing:
        parser.error(f"{', '.join(missing)} not in {args.fmu_dir}: build them with `make fmus`")
    try:
        choice = choose(args.soil, None, (), args.rover)
        plan = plan_for(choice)
    except NotDrivable as error:
        parser.error(f"not drivable: {error}")
    except ValueError as error:
        parser.error(str(error))
    rover = choice.rover
    print(f"rover {choice.rover_name}: {rover.mass:g} kg on {rover.wheels} wheels ({choice.wheel_name} wheel), "
          f"static wheel load {rover.static_wheel_load(choice.soil.gravity):.1f} N on {choice.soil_name}")
    print(f"plan: {plan.basis}")
    lateral = None
    if args.quick:  # every other load; short runs; the lateral sweep at four slip angles
        plan = replace(plan, loads=plan.loads[::2])
        lateral = SweepPlan(loads=plan.loads, torques=plan.torques, slip_angles_deg=(0.0, 5.0, 10.0, 25.0),
                            stop_time=0.02, sample_time=1e-3)
    out = output_folder(parser, args.out)
    sweep = SweepPlan(loads=plan.loads, torques=plan.torques, stop_time=0.02 if args.quick else 0.1)
    identified = run_identification(args.fmu_dir / "SingleWheel.fmu", out / "identification", plan=sweep,
                                    lateral_plan=lateral, identification=plan, workers=args.workers, choice=choice)
    print("identification: Fit of Fx (Eq. 15) "
          + ", ".join(f"{w:g} N {f:.1f} %" for w, f in zip(identified.fit["load_N"], identified.fit["fit_percent"])))
    simulated = run_simulation(args.fmu_dir, out / "identification" / "model.json", out / "simulation", choice)
    for plant, table in simulated.rms.items():
        checks = simulated.record["checks"][plant]
        print(f"closed loop ({plant}, {len(table)} wheels): RMS(Fx - Fx_des) per limb "
              + " / ".join(f"{v:.3f}" for v in table["rms_N"]) + f" N; final speed {checks['final_v_m_s']:.3f} m/s")
    print(f"wrote {len(identified.files) + len(simulated.files)} files under {out} (identification/, simulation/)")


if __name__ == "__main__":
    main()
