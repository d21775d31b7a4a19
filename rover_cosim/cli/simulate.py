"""``rover-cosim simulate``: the paper's Sec. 4 closed loop, then the path and terrain scenarios."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from typing import Any

from .command import Command
from .options import (
    add_fmu_dir,
    add_model,
    add_out,
    add_quiet,
    add_soil_options,
    choice_of,
    fail,
    fmu_dir_exists,
    model_readable,
    option_ok,
    output_folder,
    print_written,
)

#: The parts of ``simulate`` (--only), in the order they run.
PARTS = ("straight", "path", "terrain", "legwheel", "effects")


def arguments(parser: argparse.ArgumentParser) -> None:
    add_out(parser, "results/simulation")
    add_fmu_dir(parser)
    add_model(parser, "identified model (from `rover-cosim identify`)")
    parser.add_argument("--only", choices=PARTS, default=None,
                        help="only the paper's straight run, only the path following, only the terrain "
                             "scenarios (side-slope traverses) or only the leg-wheel rover's (LegWheelRover.fmu: "
                             "the straight run and a 20 deg side slope with and without posture control; the "
                             "paper's rover only) or only the wheel effects (the straight run with grousers, "
                             "slip-sinkage and multi-pass ruts each switched on: their ablation of Table 3); "
                             "default: all five (the leg-wheel part only for the paper's rover)")
    parser.add_argument("--allow-model-mismatch", action="store_true",
                        help="use a model identified on another soil or wheel (refused otherwise; recorded)")
    parser.add_argument("--adapt", action="store_true",
                        help="also run the straight run with the adaptive controller: a calibration phase, the "
                        "soil estimated from the rover's telemetry, the model identified again on SingleWheel.fmu "
                        "(implies --allow-model-mismatch: the point is a soil the model was not identified on)")
    parser.add_argument("--ruts", action="store_true",
                        help="the paper's straight run (both plants and the fixed-load ablation) with multi-pass "
                        "ruts: each wheel rolls in the rut the wheels ahead left, on soil they compacted (issue 48; "
                        "the effects part compares with and without)")
    parser.add_argument("--calibration", type=float, default=3.0, metavar="SECONDS",
                        help="with --adapt: the calibration phase's length [s] (default 3)")
    parser.add_argument("--sinkage-sensor", action="store_true",
                        help="with --adapt: the rover measures its wheels' sinkage (the estimate uses it)")
    parser.add_argument("--optional-parameters", action="store_true",
                        help="with --adapt: the soil estimate also tries a1, a0 and lambda, as estimate-soil does "
                        "(several times slower; default: they keep the model's soil's values)")
    parser.add_argument("--record-interval", type=float, default=0.01,
                        help="rows kept in the trajectory files [s] (a whole number of 1 ms steps; default 0.01; "
                        "0.001: every step); metrics and figures use every step")
    parser.add_argument("--crossing-soil", default="hit_lss1", metavar="SOIL",
                        help="the soil crossing's second soil, beyond its boundary: a library name, a TOML file or "
                        "FILE:NAME (default: hit_lss1)")
    parser.add_argument("--crossing-belief", default=None, metavar="SOIL",
                        help="the second soil the soil crossing's controller believes in (its models are identified "
                        "on it), e.g. the soil.toml of `rover-cosim estimate-soil` (default: --crossing-soil)")
    add_quiet(parser, "no progress bars")
    add_soil_options(parser)


def _calibration(args: argparse.Namespace) -> Any:
    """The adaptive run's Calibration of --calibration, --sinkage-sensor and --optional-parameters
    (None without --adapt)."""
    from rover_cosim.control.calibration import Calibration

    return Calibration(duration=args.calibration, sinkage_sensor=args.sinkage_sensor,
                       optional_parameters=args.optional_parameters) if args.adapt else None


def _crossing_soils_known(args: argparse.Namespace) -> bool:
    """Whether the soil crossing's soils (--crossing-soil, --crossing-belief) are known; else says why."""
    from rover_cosim.terramechanics.library import choose

    for option, name in (("--crossing-soil", args.crossing_soil), ("--crossing-belief", args.crossing_belief)):
        try:
            if name is not None:
                choose(soil=name)
        except ValueError as error:
            fail("simulate", f"{option}: {error}")
            return False
    return True


def run(args: argparse.Namespace) -> int:
    from rover_cosim.jobs.straight_run import check_options
    from rover_cosim.orchestrator.master import RunError
    from rover_cosim.orchestrator.system import SystemFileError

    if not output_folder(args.out, "simulate", COMMAND.needs_bytes) or not fmu_dir_exists(args.fmu_dir, "simulate"):
        return 2
    if not option_ok("simulate", "--record-interval", lambda: check_options(args.record_interval)) or not option_ok(
            "simulate", "--calibration", lambda: check_options(args.record_interval, _calibration(args))):
        return 2
    calibration = _calibration(args)
    if not model_readable(args.model, "simulate"):
        return 2
    choice = choice_of(args, "simulate")
    if choice is None:
        return 2
    if args.only in (None, "terrain") and not _crossing_soils_known(args):
        return 2
    try:
        _runs(args, choice, calibration)
    except (SystemFileError, RunError, ValueError) as error:
        fail("simulate", f"{error} (nothing written)")
        return 1
    return 0


def _runs(args: argparse.Namespace, choice: Any, calibration: Any) -> None:
    """The parts asked for (``--only``; all of PARTS by default, the leg-wheel part only for the
    paper's rover), each run under its progress bar, printed and writing its files."""
    from rover_cosim.progress import ProgressBar

    allow = args.allow_model_mismatch or args.adapt
    for part in PARTS:
        if args.only not in (None, part) or (args.only is None and part == "legwheel"
                                             and choice.rover_name != "paper"):
            continue
        title, run, show = _PART_RUNS[part]
        bar = ProgressBar(f"simulate: {title}", enabled=not args.quiet)
        outcome = run(args, choice, allow, calibration, bar)
        bar.close()
        show(outcome)


def _straight(args: argparse.Namespace, choice: Any, allow: bool, calibration: Any, bar: Any) -> Any:
    from rover_cosim.jobs.simulate import run_simulation

    return run_simulation(args.fmu_dir, args.model, args.out, choice, allow_model_mismatch=allow, progress=bar,
                          record_interval=args.record_interval, adapt=calibration, ruts=args.ruts)


def _path(args: argparse.Namespace, choice: Any, allow: bool, calibration: Any, bar: Any) -> Any:
    from rover_cosim.jobs.path_following import run_path_following

    return run_path_following(args.fmu_dir, args.model, args.out, choice=choice, allow_model_mismatch=allow,
                              progress=bar, record_interval=args.record_interval)


def _terrain(args: argparse.Namespace, choice: Any, allow: bool, calibration: Any, bar: Any) -> Any:
    from rover_cosim.jobs.terrain import SoilCrossingScenario, run_terrain

    crossing = SoilCrossingScenario(soil_b=args.crossing_soil, believed_soil_b=args.crossing_belief)
    return run_terrain(args.fmu_dir, args.model, args.out, choice=choice, allow_model_mismatch=allow, progress=bar,
                       record_interval=args.record_interval, crossing=crossing)


def _legwheel(args: argparse.Namespace, choice: Any, allow: bool, calibration: Any, bar: Any) -> Any:
    from rover_cosim.jobs.legwheel import run_legwheel

    return run_legwheel(args.fmu_dir, args.model, args.out, choice=choice, allow_model_mismatch=allow, progress=bar,
                        record_interval=args.record_interval)


def _effects(args: argparse.Namespace, choice: Any, allow: bool, calibration: Any, bar: Any) -> Any:
    from rover_cosim.jobs.effects import run_effects

    return run_effects(args.fmu_dir, args.model, args.out, choice=choice, allow_model_mismatch=allow, progress=bar)


def _print_path(outcome: Any) -> None:
    columns = {"cross_track_rms_m": "cross-track RMS [m]", "cross_track_max_m": "max [m]",
               "speed_error_max_percent": "speed error [%]"}
    table = outcome.metrics[["scenario", "run", *columns]].rename(columns=columns)
    rms = outcome.metrics.filter(like="rms_F")
    table["largest RMS(Fx - Fx_des) [N]"] = rms.filter(like="rms_Fx").max(axis=1)
    table["largest RMS(Fy - Fy_des) [N]"] = rms.filter(like="rms_Fy").max(axis=1)
    print(table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    print_written(outcome.files)


def print_effects(outcome: Any) -> None:
    """What the wheel-effects ablation measured (jobs.effects.EffectsResult): Table 1 and, per run, the
    sinkage and RMS(Fx - Fx_des) of one side's wheels (the other mirrors it on the straight run)."""
    print("Table 1 with each wheel effect on: Fit [%] on the variant's test bed of the given model (--model) and "
          "of the variant's own:")
    fits = outcome.table1.melt(id_vars=["variant", "load_N"], var_name="model", value_name="fit")
    fits["model"] = fits["model"].str.removeprefix("fit_percent_")
    order = [(v, m) for v in outcome.table1["variant"].unique() for m in fits["model"].unique()]
    print(fits.pivot(index=["variant", "model"], columns="load_N", values="fit").reindex(order)
          .rename(columns=lambda load: f"{load:g} N").to_string(float_format=lambda v: f"{v:.1f}"))
    ablation = outcome.ablation
    half = sorted(ablation["wheel"].unique())[: max(1, ablation["wheel"].nunique() // 2)]
    print(f"The straight run with each effect on, at cruise, wheels {', '.join(map(str, half))}:")
    runs = ablation[ablation["wheel"].isin(half)].pivot(index=["variant", "model"], columns="wheel",
                                                          values=["sinkage_mean_m", "rms_N"])
    runs = runs.reindex(ablation[["variant", "model"]].drop_duplicates().itertuples(index=False))
    runs.columns = [f"{'sinkage [mm]' if name == 'sinkage_mean_m' else 'RMS [N]'} {wheel}"
                    for name, wheel in runs.columns]
    runs[[c for c in runs.columns if c.startswith("sinkage")]] *= 1e3
    print(runs.to_string(float_format=lambda v: f"{v:.3g}"))
    turn = outcome.path_sinkage.set_index(["phase", "wheel"]) * 1e3
    print("The turn without and with ruts, mean per phase [mm]:")
    print(turn.rename(columns={"sinkage_virgin_m": "sinkage, virgin soil", "sinkage_ruts_m": "sinkage, ruts",
                               "rut_depth_m": "rut under the wheel"}).to_string(float_format=lambda v: f"{v:.3g}"))
    print_written(outcome.files)


def print_legwheel(outcome: Any) -> None:
    """What the leg-wheel scenarios measured (jobs.legwheel.LegWheelResult)."""
    print("Leg-wheel rover, the paper's straight run (Table 3, limbs 4-6 mirror 1-3):")
    print(outcome.rms.rename(columns={"rms_legwheel_N": "RMS(Fx - Fx_des), LegWheelRover.fmu [N]",
                                      "rms_legwheel_cosim_N": "LegWheelRoverBody + 6 Wheel [N]",
                                      "rms_spring_damper_N": "Rover.fmu [N]", "rms_paper_N": "paper [N]"})
          .to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    columns = {"load_spread": "load max/min", "sinkage_spread_m": "sinkage spread [m]",
               "cross_track_rms_m": "cross-track RMS [m]", "cross_track_max_m": "max [m]",
               "energy_per_metre_J_m": "energy [J/m]", "roll_end_deg": "roll at the end [deg]"}
    slope = outcome.record["parameters"]["slope_deg"]
    metrics = outcome.metrics
    print(f"Leg-wheel rover across a {slope:g} deg side slope:")
    print(metrics[metrics["scenario"] == "slope"][["run", *columns]].rename(columns=columns).to_string(
        index=False, float_format=lambda v: f"{v:.3g}"))
    patch = {"distance_m": "distance [m]", "mean_speed_m_s": "mean speed [m/s]", "energy_per_metre_J_m": "energy [J/m]",
             "sinkage_1_max_m": "front-left sinkage max [m]", "in_patch_s": "in the patch [s]"}
    print("Leg-wheel rover, the front-left wheel in a soft patch:")
    print(metrics[metrics["scenario"] == "patch"][["run", *patch]].rename(columns=patch).to_string(
        index=False, float_format=lambda v: f"{v:.3g}"))
    print_written(outcome.files)


def _print_terrain(outcome: Any) -> None:
    columns = {"side_slope_deg": "side slope [deg]", "cross_track_rms_m": "cross-track RMS [m]",
               "cross_track_max_m": "max [m]", "heading_error_max_rad": "heading error max [rad]",
               "energy_per_metre_J_m": "energy [J/m]"}
    table = outcome.metrics[["scenario", "run", *columns]].rename(columns=columns)
    print(table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    print_written(outcome.files)


def print_straight(outcome: Any) -> None:
    """What the paper's straight run measured (jobs.simulate.SimulationResult): its checks, Table 3,
    the adaptive run's estimate, the files."""
    import pandas as pd

    print("Velocity and loads:")
    print(outcome.checks_table().to_string(float_format=lambda v: f"{v:.4g}"))
    wheels = len(outcome.rms["cosim"])
    fixed = outcome.record["parameters"].get("fixed_load_ablation_N", float("nan"))
    table = pd.DataFrame({"limb": outcome.rms["monolithic"]["limb"],
                          "RMS(Fx - Fx_des), Rover.fmu [N]": outcome.rms["monolithic"]["rms_N"],
                          f"RMS, RoverBody + {wheels} Wheel [N]": outcome.rms["cosim"]["rms_N"],
                          f"RMS, one model at {fixed:.0f} N [N]": outcome.ablation["rms_fixed_load_N"]})
    side = wheels // 2
    print(f"Table 3 (limbs {side + 1}-{wheels} mirror 1-{side}):")
    print(table.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    adaptation = outcome.record.get("adaptation")
    if adaptation:
        soil = adaptation.get("estimated_soil") or {}
        print(f"Adaptive run: the model switched at {adaptation['switched_at_s']:g} s after "
              f"{adaptation['samples']} calibration samples ({adaptation['adapt_wall_s']:.1f} s to estimate and "
              f"identify); estimated c {soil.get('c', float('nan')):.4g} Pa, phi "
              f"{math.degrees(soil.get('phi', float('nan'))):.3g} deg, k_phi {soil.get('kphi', float('nan')):.4g}, "
              f"n {soil.get('n', float('nan')):.3g}, k_x {soil.get('kx', float('nan')):.3g} m; largest "
              f"RMS(Fx - Fx_des) after the calibration {max(adaptation['rms_after_calibration_N']):.3f} N "
              f"(nominal model: {max(adaptation['rms_after_calibration_nominal_model_N']):.3f} N)")
    print_written(outcome.files)


#: Each part of PARTS: its progress bar's title, how it runs, how its outcome is printed.
_PART_RUNS: dict[str, tuple[str, Callable[..., Any], Callable[[Any], None]]] = {
    "straight": ("the paper's straight run", _straight, print_straight),
    "path": ("path following", _path, _print_path),
    "terrain": ("side-slope traverses", _terrain, _print_terrain),
    "legwheel": ("the leg-wheel rover", _legwheel, print_legwheel),
    "effects": ("grousers, slip-sinkage, multi-pass", _effects, print_effects),
}


def result_sets(args: argparse.Namespace) -> int | None:
    """One result set per part run (each writes its files into the folder as one set)."""
    if args.only:
        return 1
    rover = getattr(args, "rover", None)
    return len(PARTS) if rover in (None, "paper") else len(PARTS) - 1  # the leg-wheel part: the paper's rover


COMMAND = Command(
    "simulate", help="paper Sec. 4: closed-loop rover, 20 s, on Rover.fmu and on RoverBody + 6 Wheel; then the "
    "steerable rover following a turn and a lane change -> results/simulation/",
    summary="Paper Sec. 4: the closed-loop rover on Rover.fmu and RoverBody + 6 Wheel, then path following.",
    examples=("rover-cosim simulate --out results/simulation", "rover-cosim simulate --only straight --quiet"),
    arguments=arguments, run=run, needs_bytes=60e6, result_sets=result_sets)

