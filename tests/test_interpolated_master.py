"""The Gauss-Seidel master with interpolated inputs (``gauss-seidel-interpolated``): an FMU that can
interpolate its inputs takes those another FMU before it has moved to t + h as a ramp over the step
(fmi2SetRealInputDerivatives); a block's outputs are held unless it declares them ``ramped_outputs``.
Checked against the monolithic rover (the cut's error shrinks), against plain Gauss-Seidel where
nothing can ramp (bit for bit), a block's declared ramp against a fine step, the native stepper
against the Python master (tests/test_native.py too), and on the leg-wheel rover in
tests/test_legwheel.py (path after 4 s)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from rover_cosim.jobs.cosim_study import _system
from rover_cosim.orchestrator.master import run


def _velocity_error(fmu_dir, algorithm: str, step: float, stop: float) -> tuple[float, np.ndarray]:
    mono = run(_system("rover_open_loop", fmu_dir, step=step, stop_time=stop, algorithm="gauss-seidel")).data
    cosim = run(_system("rover_cosim", fmu_dir, step=step, stop_time=stop, algorithm=algorithm)).data
    return float(np.abs(cosim["body.v"] - mono["rover.v"]).max()), cosim["body.v"].to_numpy()


def test_the_co_simulated_rover_follows_the_monolithic_one_closer_with_interpolated_hub_speeds(fmus):
    """RoverBody + 6 Wheel against Rover.fmu (open loop, 1 ms, 1 s): the wheels see each hub's speed
    rise through the step instead of its end value held (half a step ahead): the body's speed error
    is at least four times smaller than plain Gauss-Seidel's (measured: 3.0e-3 -> 3.5e-4 m/s over 2 s)."""
    fmu_dir = fmus["Rover"].parent
    plain, _ = _velocity_error(fmu_dir, "gauss-seidel", 1e-3, 1.0)
    ramped, _ = _velocity_error(fmu_dir, "gauss-seidel-interpolated", 1e-3, 1.0)
    assert ramped < plain / 4, (plain, ramped)


def test_without_an_fmu_fed_by_another_fmu_it_is_gauss_seidel_bit_for_bit(fmus):
    """The monolithic rover driven by blocks only (nothing an FMU gives another): the same numbers
    as Gauss-Seidel, row for row (the blocks' outputs are held, not ramped)."""
    fmu_dir = fmus["Rover"].parent
    runs = [run(_system("rover_open_loop", fmu_dir, step=1e-3, stop_time=0.2, algorithm=a)).data
            for a in ("gauss-seidel", "gauss-seidel-interpolated")]
    assert list(runs[0].columns) == list(runs[1].columns)
    np.testing.assert_array_equal(runs[0].to_numpy(), runs[1].to_numpy())


class TorqueRamp:
    """A block whose output moves linearly in time (tau = 400 N.m/s t from 50 N.m: the wheel spins up), declared a ramp;
    it reads the wheel's speed (so that it steps before the wheel, not as a source after it)."""

    def __init__(self, name: str, ramped: bool):
        self.name = name
        self.inputs: tuple[str, ...] = ("omega",)
        self.outputs: tuple[str, ...] = ("tau",)
        self.units: dict[str, str] = {"omega": "rad/s", "tau": "N.m"}
        self.feedthrough = True
        self.ramped_outputs: tuple[str, ...] = ("tau",) if ramped else ()

    def start(self, t0: float, u0: np.ndarray, h: float | None = None) -> np.ndarray:
        return np.array([50.0 + 400.0 * t0])

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        return np.array([50.0 + 400.0 * (t + h)])


def _wheel_spin(fmu_dir, step: float, ramped: bool, algorithm: str = "gauss-seidel-interpolated",
                native: bool = True) -> pd.DataFrame:
    from rover_cosim.orchestrator.builder import SystemBuilder

    builder = SystemBuilder("a torque ramp on Wheel.fmu").simulation(stop_time=0.5, step=step, algorithm=algorithm,
                                                                     native=native)
    builder.add_fmu("wheel", fmu_dir / "Wheel.fmu", start={"W": 424.0, "v_hub": 0.0})
    builder.add_block("torque", TorqueRamp("torque", ramped))
    builder.connect("wheel.omega", "torque.omega").connect("torque.tau", "wheel.tau")
    builder.record("wheel.omega", "wheel.slip")
    return run(builder.simulation(order=["torque", "wheel"]).build()).data


def test_a_blocks_declared_ramped_outputs_reach_the_fmu_as_ramps_natively_as_from_python(fmus):
    """A block declaring ``ramped_outputs`` (a torque rising linearly) feeds Wheel.fmu: under the
    interpolated master the wheel takes it as the line over each step, so that at a 10 ms step its
    spin is far closer to a 0.1 ms reference than with the torque held at the step's end value
    (Gauss-Seidel, or the same block not declaring it; measured after 0.5 s: 0.012 rad/s off
    against 1.2); the native stepper ramps it as the Python master does, bit for bit."""
    fmu_dir = fmus["Wheel"].parent
    reference = _wheel_spin(fmu_dir, 1e-4, False, "gauss-seidel")["wheel.omega"].iloc[-1]
    held = _wheel_spin(fmu_dir, 1e-2, False)["wheel.omega"].iloc[-1]
    plain = _wheel_spin(fmu_dir, 1e-2, True, "gauss-seidel")["wheel.omega"].iloc[-1]
    ramped = _wheel_spin(fmu_dir, 1e-2, True)
    assert held == plain  # not declared, or not interpolated: held
    assert abs(ramped["wheel.omega"].iloc[-1] - reference) < abs(held - reference) / 4, (reference, held, ramped)
    from_python = _wheel_spin(fmu_dir, 1e-2, True, native=False)
    pd.testing.assert_frame_equal(ramped, from_python, check_exact=True)


def test_a_ramped_output_that_is_not_an_output_is_refused_with_its_name():
    from rover_cosim.orchestrator.builder import SystemBuilder
    from rover_cosim.orchestrator.system import SystemFileError

    block = TorqueRamp("torque", True)
    block.ramped_outputs = ("tau", "torque")
    with pytest.raises(SystemFileError, match=r"ramped_outputs \['torque'\]: not outputs of the block"):
        SystemBuilder("s").add_block("torque", block)
