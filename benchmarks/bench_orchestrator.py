"""Benchmark of the co-simulation master: the co-simulated rover (RoverBody + 6 Wheel FMUs) over
20 s at a 1 ms communication step, run by our orchestrator (Jacobi and Gauss-Seidel, FMUs
stepped from C in threads as by default, and Jacobi with the Python master for comparison) and
by libcosimpy (Open Simulation Platform's libcosim, fixed-step) and ecospy (Ecos, which steps the
FMUs on all cores) on the same FMUs in the same run. ecospy needs Debian's libtbb12: where it
cannot be loaded the benchmark says why and goes on without it.

The torques are constant start values (20 N·m on every wheel and as reaction on the body), so
the system has FMUs only and libcosim runs it in one ``simulate_until`` call. Reported: wall time,
wall time per step, and our master's overhead per step (wall time minus the time spent inside
the FMU calls, i.e. the Python master's own work). Written to results/bench/orchestrator.json
by ``make bench``. Not a test: nothing asserts a time; the floor of issue 5 (within 3x of
libcosim's wall time) is recorded beside the measured ratio.

Beside the runs inside this process, the whole processes a user waits for: ``rover-cosim run`` of
the same system (written as a system file) from start to exit (imports, unpacking, the run, the
CSV), and Ecos in a process of its own that imports ecospy and runs the same FMUs
(``*_process`` variants, their own ratio): Ecos as it comes (recording nothing), and Ecos with its
CSV writer recording the same columns at every step (``ecospy_csv_process``: the same output as
ours, at Ecos' six decimals). Each process runs once before the timed rounds, so that Python's
bytecode caches are written as in a user's installation.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path
from typing import Any

from rover_cosim.common.outputs import json_bytes, run_record, write_all
from rover_cosim.fmubuild import build
from rover_cosim.orchestrator.examples import example
from rover_cosim.orchestrator.libcosim import run_libcosim
from rover_cosim.orchestrator.master import run
from rover_cosim.orchestrator.native import unavailable_reason
from rover_cosim.orchestrator.system import system_from_dict, system_to_toml

SYSTEM = example("rover_cosim")
FLOOR_RATIO = 3.0
TORQUE = 20.0  # N·m


def bench_system(algorithm: str, stop_time: float, step: float, native: bool = True):
    data = tomllib.loads(SYSTEM.read_text())
    data["simulation"].update(algorithm=algorithm, stop_time=stop_time, step=step, native=native)
    data.pop("block")
    data["connection"] = [c for c in data["connection"] if not c["from"].startswith("torque.")]
    for fmu in data["fmu"]:
        if fmu["name"] == "body":
            fmu["start"] = {f"tau[{i}]": TORQUE for i in range(1, 7)}
        else:
            fmu["start"] = {"tau": TORQUE}
    data["simulation"]["order"] = [f["name"] for f in data["fmu"]]
    return system_from_dict(data, name="bench rover_cosim", base=Path("fmus").resolve(), path=SYSTEM)


def ecospy_missing() -> str | None:
    """Why ecospy cannot run here, or None."""
    try:
        import ecospy  # noqa: F401  (loads libecosc.so, which needs libtbb12)
    except ImportError as error:
        return f"ecospy not installed ({error}); pip install ecospy"
    except OSError as error:
        return f"ecospy's library does not load ({error}); on Debian: apt install libtbb12"
    return None


def run_ecospy(system: Any) -> tuple[float, float]:
    """Wall seconds of ``system`` (FMUs only, Jacobi-like fixed step) run by Ecos, and the body's
    final velocity [m/s]."""
    from ecospy import EcosSimulation, EcosSimulationStructure

    started = time.perf_counter()
    with EcosSimulationStructure() as structure:
        for fmu in system.fmus:
            structure.add_model(fmu.name, str(fmu.path))
        for connection in system.connections:
            structure.make_real_connection(f"{connection.source.instance}::{connection.source.variable}",
                                           f"{connection.target.instance}::{connection.target.variable}")
        values = {f"{fmu.name}::{name}": float(value) for fmu in system.fmus
                  for name, value in {**fmu.parameters, **fmu.start}.items()}
        structure.add_parameter_set("initial", values)
        with EcosSimulation(structure=structure, step_size=system.step) as simulation:
            simulation.init(parameter_set="initial")
            simulation.step_until(system.stop_time)
            final_v = simulation.get_real("body::v")
            simulation.terminate()
    return time.perf_counter() - started, final_v


#: Ecos run as a process of its own: the system's FMUs, connections and values from a JSON file.
ECOSPY_PROCESS = """
import json, sys
from ecospy import EcosSimulation, EcosSimulationStructure
spec = json.load(open(sys.argv[1]))
with EcosSimulationStructure() as structure:
    for name, path in spec["fmus"]:
        structure.add_model(name, path)
    for source, target in spec["connections"]:
        structure.make_real_connection(source, target)
    structure.add_parameter_set("initial", spec["values"])
    with EcosSimulation(structure=structure, step_size=spec["step"]) as simulation:
        if spec["csv"]:
            simulation.add_csv_writer(spec["csv"], identifiers=spec["record"])
        simulation.init(parameter_set="initial")
        simulation.step_until(spec["stop_time"])
        print("final body.v", simulation.get_real("body::v"))
        simulation.terminate()
"""


def process_files(folder: Path, stop_time: float, step: float, csv: bool = False) -> tuple[Path, Path]:
    """The benchmark's system as a system file (for ``rover-cosim run``) and as Ecos' JSON (with
    ``csv``: Ecos records the system's recorded ports to a CSV file in ``folder``)."""
    system = bench_system("jacobi", stop_time, step)
    toml = folder / "bench_rover_cosim.toml"
    toml.write_text(system_to_toml(system, folder))
    spec = {"fmus": [(fmu.name, str(fmu.path)) for fmu in system.fmus],
            "connections": [(f"{c.source.instance}::{c.source.variable}", f"{c.target.instance}::{c.target.variable}")
                            for c in system.connections],
            "values": {f"{fmu.name}::{name}": float(value) for fmu in system.fmus
                       for name, value in {**fmu.parameters, **fmu.start}.items()},
            "step": system.step, "stop_time": system.stop_time,
            "csv": str(folder / "ecos.csv") if csv else None,
            "record": [f"{port.instance}::{port.variable}" for port in system.record]}
    ecos = folder / "bench_ecos.json"
    ecos.write_text(json.dumps(spec))
    return toml, ecos


def run_process(name: str, stop_time: float, step: float) -> tuple[float, float | None, float | None]:
    """One whole process of ``name`` (``ours_jacobi_process`` or ``ecospy_process``): its wall
    seconds from start to exit, and the body's final velocity [m/s] where it prints one."""
    with tempfile.TemporaryDirectory(prefix="bench-process-") as folder:
        toml, ecos = process_files(Path(folder), stop_time, step, csv=name == "ecospy_csv_process")
        if name.startswith("ecospy"):
            argv = [sys.executable, "-P", "-c", ECOSPY_PROCESS, str(ecos)]
        else:
            argv = [sys.executable, "-P", "-m", "rover_cosim", "run", str(toml), "-q", "-o",
                    str(Path(folder) / "out.csv")]
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}  # as installed
        started = time.perf_counter()
        done = subprocess.run(argv, capture_output=True, text=True, check=False, env=env)
        wall = time.perf_counter() - started
        if done.returncode != 0:
            raise RuntimeError(f"{name}: exit {done.returncode}: {done.stderr[-2000:]}")
        said = [line.split()[-1] for line in done.stdout.splitlines() if line.startswith("final body.v")]
        final = float(said[-1]) if said else None
        return wall, None, final


def run_variant(name: str, stop_time: float, step: float) -> tuple[float, float | None, float | None]:
    """One run of the variant ``name``: wall seconds, our master's overhead [s] and the body's
    final velocity [m/s] (None where the tool does not give them)."""
    if name.endswith("_process"):
        return run_process(name, stop_time, step)
    if name == "ecospy":
        wall, final_v = run_ecospy(bench_system("jacobi", stop_time, step))
        return wall, None, final_v
    if name == "libcosim":
        return run_libcosim(bench_system("jacobi", stop_time, step), record=False).wall_seconds, None, None
    algorithm = "gauss-seidel" if name == "ours_gauss_seidel" else "jacobi"
    result = run(bench_system(algorithm, stop_time, step, native=name != "ours_jacobi_python_master"))
    return result.wall_seconds, result.master_overhead_seconds, float(result.data["body.v"].iloc[-1])


def measure(names: tuple[str, ...], repeats: int, stop_time: float, step: float) -> dict[str, dict[str, Any]]:
    """``repeats`` rounds of one run of every variant (interleaved, so that a slower spell of the
    machine hits all alike): per variant its entry (:func:`summary`)."""
    runs: dict[str, list[tuple[float, float | None, float | None]]] = {name: [] for name in names}
    for name in names:
        if name.endswith("_process"):  # once untimed: bytecode caches written, files in the page cache
            run_variant(name, min(stop_time, 0.1), step)
    for _ in range(repeats):
        for name in names:
            runs[name].append(run_variant(name, stop_time, step))
    return {name: summary(outcomes, round(stop_time / step)) for name, outcomes in runs.items()}


def summary(outcomes: list[tuple[float, float | None, float | None]], steps: int) -> dict[str, Any]:
    """Wall times, their median per step, ours' master overhead and the final velocity."""
    walls = [wall for wall, _, _ in outcomes]
    overheads = [overhead for _, overhead, _ in outcomes if overhead is not None]
    finals = [final for _, _, final in outcomes if final is not None]
    entry: dict[str, Any] = {"wall_seconds": walls, "wall_seconds_median": statistics.median(walls),
                             "wall_per_step_us_median": 1e6 * statistics.median(walls) / steps}
    if overheads:  # negative where the FMUs step on several threads at once (their times add up)
        entry["master_overhead_seconds"] = overheads
    if finals:
        entry["final_body_v_m_s"] = finals[-1]
    return entry


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", type=Path, default=Path("results/bench/orchestrator.json"))
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--stop-time", type=float, default=20.0)
    parser.add_argument("--step", type=float, default=1e-3)
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error(f"--repeats={args.repeats}: expected an integer >= 1")

    build.build_all(build.FMU_MODELS, Path("fmus"), backend="builtin")
    steps = round(args.stop_time / args.step)
    missing = ecospy_missing()
    if missing:
        print(f"ecospy skipped: {missing}")
    native_missing = unavailable_reason()
    if native_missing:
        print(native_missing)
    names = ("ours_jacobi", "ours_gauss_seidel", "ours_jacobi_python_master", "libcosim", "ours_jacobi_process") + (
        () if missing else ("ecospy", "ecospy_process", "ecospy_csv_process"))
    results = measure(names, args.repeats, args.stop_time, args.step)
    for name, entry in results.items():
        print(f"{name:26s} {entry['wall_seconds_median']:6.2f} s for {steps} steps "
              f"({entry['wall_per_step_us_median']:.0f} us/step)")
    ratios = {name: results[name]["wall_seconds_median"] / results["libcosim"]["wall_seconds_median"]
              for name in ("ours_jacobi", "ours_gauss_seidel", "ours_jacobi_python_master")}
    print("wall time / libcosim: " + ", ".join(f"{k} {v:.2f}x" for k, v in ratios.items())
          + f" (floor {FLOOR_RATIO:.0f}x)")
    to_ecospy = ({name: results[name]["wall_seconds_median"] / results["ecospy"]["wall_seconds_median"]
                  for name in ("ours_jacobi", "ours_gauss_seidel", "ours_jacobi_python_master")}
                 if "ecospy" in results else None)
    if to_ecospy:
        print("wall time / ecospy: " + ", ".join(f"{k} {v:.2f}x" for k, v in to_ecospy.items()) + " (goal <= 1)")
    whole = (results["ours_jacobi_process"]["wall_seconds_median"] / results["ecospy_process"]["wall_seconds_median"]
             if "ecospy_process" in results else None)
    whole_csv = (results["ours_jacobi_process"]["wall_seconds_median"]
                 / results["ecospy_csv_process"]["wall_seconds_median"] if "ecospy_csv_process" in results else None)
    if whole is not None and whole_csv is not None:
        print(f"whole process, rover-cosim run / ecospy: {whole:.2f}x (goal <= 1); "
              f"/ ecospy writing the same columns to CSV: {whole_csv:.2f}x")
    record = run_record("make bench", {"repeats": args.repeats, "stop_time_s": args.stop_time, "step_s": args.step,
                                       "torque_N_m": TORQUE, "fmus": 7, "cpus": os.cpu_count()})
    write_all({args.out: json_bytes({**record, "results": results, "ratio_to_libcosim": ratios,
                                     "floor_ratio": FLOOR_RATIO,
                                     "floor_met": all(r <= FLOOR_RATIO for r in ratios.values()),
                                     "ratio_to_ecospy": to_ecospy, "ecospy_skipped": missing,
                                     "whole_process_ratio_to_ecospy": whole,
                                     "whole_process_ratio_to_ecospy_writing_csv": whole_csv,
                                     "goal_ratio_to_ecospy": 1.0,
                                     "note": "libcosim and Ecos step their slaves on worker threads; ours steps "
                                             "them in threads as well (one per core by default)"})})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
