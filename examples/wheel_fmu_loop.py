"""The Wheel FMU in your own FMPy loop.

A hand-written FMI 2.0 co-simulation loop over FMPy on fmus/Wheel.fmu: the soil and wheel are set
through the FMU's parameters (``soil.c``, ``soil.phi``, ..., ``wheel.r``), then every step sets the
inputs (drive torque, load, hub speed), calls ``doStep`` and reads the outputs. The hub moves at a
constant speed, as on a test bed, and the drive torque rises in steps; at each step the wheel's
spin settles (within ~20 ms) where the soil's resistance torque equals the drive torque. At the
end of each torque level the numpy reference wheel is evaluated at the FMU's load and slip, and
the drawbar pull, load, torque and sinkage of the two are compared.

    python examples/wheel_fmu_loop.py --out wheel_loop       # needs fmus/Wheel.fmu (make fmus)

Writes <out>/wheel_fmu_loop.csv (the trajectory) and <out>/wheel_fmu_loop.json (per torque level:
the FMU's settled state and the numpy wheel's).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
from pathlib import Path

import pandas as pd
from fmpy import extract, instantiate_fmu, read_model_description

from rover_cosim.terramechanics import wheel_state
from rover_cosim.terramechanics.library import choose, fmu_parameters

NAME = "wheel_fmu_loop"
INPUTS = ["tau", "W", "v_hub", "v_lat"]                                    # N·m, N, m/s, m/s
OUTPUTS = ["omega", "slip", "sinkage", "Fx", "Fz", "Tx", "entryAngle"]      # rad/s, -, m, N, N, N·m, rad
COMPARED = ["Fx", "Fz", "Tx", "sinkage"]                                    # N, N, N·m, m


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
    parser.add_argument("--fmu", type=Path, default=Path("fmus/Wheel.fmu"), help="the Wheel FMU (make fmus)")
    parser.add_argument("--soil", default="lunar_nominal", help="a shipped soil (rover-cosim soils) or a TOML file")
    parser.add_argument("--wheel", default="paper", help="a shipped wheel or a TOML file")
    parser.add_argument("--load", type=float, default=424.0, help="wheel load W [N]")
    parser.add_argument("--torques", default="5,10,20,30,40", help="drive torque levels [N·m], comma-separated")
    parser.add_argument("--hold", type=float, default=0.2, help="how long each torque level is held [s]")
    parser.add_argument("--speed", type=float, default=1.0, help="hub speed [m/s]")
    parser.add_argument("--step", type=float, default=1e-3, help="communication step [s]")
    parser.add_argument("--quick", action="store_true", default=bool(os.environ.get("ROVER_COSIM_EXAMPLE_QUICK")),
                        help="hold each level 0.05 s; also ROVER_COSIM_EXAMPLE_QUICK=1")
    args = parser.parse_args()
    if not args.fmu.is_file():
        parser.error(f"{args.fmu} not found: build it with `make fmus` or `rover-cosim build-fmus Wheel`")
    torques = [float(t) for t in args.torques.split(",")]
    steps_per_level = round((0.05 if args.quick else args.hold) / args.step)
    out = output_folder(parser, args.out)

    # The soil and wheel from the library, as the FMU's parameter names ({"soil.c": 170.0, ...}).
    choice = choose(args.soil, args.wheel)
    parameters = fmu_parameters(choice.soil, choice.wheel)

    description = read_model_description(args.fmu)
    vr = {variable.name: variable.valueReference for variable in description.modelVariables}
    inputs, outputs = [vr[name] for name in INPUTS], [vr[name] for name in OUTPUTS]
    unzipped = extract(args.fmu)
    fmu = instantiate_fmu(unzipped, description, fmi_type="CoSimulation")   # an instantiated fmpy FMU2Slave
    rows, time = [], 0.0
    try:
        fmu.setupExperiment(startTime=0.0, stopTime=len(torques) * steps_per_level * args.step)
        fmu.setReal([vr[name] for name in parameters], list(parameters.values()))
        fmu.setReal([vr["omega"]], [args.speed / choice.wheel.r])   # start rolling without slip: omega = v / r
        fmu.setReal(inputs, [torques[0], args.load, args.speed, 0.0])
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        for level, torque in enumerate(torques):
            for _ in range(steps_per_level):
                fmu.setReal(inputs, [torque, args.load, args.speed, 0.0])   # held over the step
                fmu.doStep(currentCommunicationPoint=time, communicationStepSize=args.step)
                time += args.step
                rows.append({"time": time, "level": level, "tau": torque,
                             **dict(zip(OUTPUTS, fmu.getReal(outputs)))})
        fmu.terminate()
    finally:
        fmu.freeInstance()
        shutil.rmtree(unzipped, ignore_errors=True)
    trajectory = pd.DataFrame(rows)

    # The numpy reference wheel at the FMU's state at the end of each level: the same load and
    # slip, its sinkage solved so that Fz = W.
    settled = trajectory.groupby("level").last()
    reference = wheel_state(args.load, settled["slip"].to_numpy(), choice.wheel, choice.soil)
    compared = [{"tau_N_m": float(row.tau), "slip": float(row.slip),
                 **{f"{name}_fmu": float(getattr(row, name)) for name in COMPARED},
                 **{f"{name}_numpy": float(getattr(reference, name)[i]) for name in COMPARED}}
                for i, row in enumerate(settled.itertuples())]
    print(f"soil {choice.soil_name}, wheel {choice.wheel_name}: W = {args.load:g} N, hub at {args.speed:g} m/s")
    print("  tau [N·m]  slip [-]  drawbar pull Fx [N]: FMU     numpy  relative difference")
    for c in compared:
        fmu_fx, numpy_fx = c["Fx_fmu"], c["Fx_numpy"]
        difference = abs(fmu_fx - numpy_fx) / abs(numpy_fx)
        print(f"  {c['tau_N_m']:9.3g}  {c['slip']:8.5f}  {fmu_fx:24.5f}  {numpy_fx:8.5f}  {difference:.1e}")

    csv, record = out / f"{NAME}.csv", out / f"{NAME}.json"
    trajectory.to_csv(csv, index=False, float_format="%.12g")
    record.write_text(json.dumps({"fmu": str(args.fmu), "soil": choice.soil_name, "wheel": choice.wheel_name,
                                  "load_N": args.load, "speed_m_s": args.speed, "step_s": args.step,
                                  "hold_s": steps_per_level * args.step, "levels": compared}, indent=2))
    print(f"wrote {csv} and {record}")


if __name__ == "__main__":
    main()
