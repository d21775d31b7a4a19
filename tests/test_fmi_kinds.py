"""FMUs of every kind the engine runs, on test FMUs of our own (tests/fmus): Model Exchange FMUs
integrated by the engine (ball2.c, FMI 2.0 ME only: state and time events, a continuous input, an
FMU ending the simulation), FMI 3.0 in Co-Simulation and Model Exchange (ball3.c, with Float32,
Int64, UInt8 and String variables), String connections and recording (typed.c), and the checks
at load (an interface the FMU does not offer, types that do not meet). The bouncing ball has an
exact solution (ball_fmus.exact_height) to compare with."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from ball_fmus import E, G, build_ball2, build_ball3, exact_height
from c_fmu import built_or_skip

from rover_cosim.cli import main
from rover_cosim.orchestrator import SystemBuilder, run
from rover_cosim.orchestrator.blocks import Constant, CsvInput
from rover_cosim.orchestrator.model import SystemFileError
from rover_cosim.orchestrator.system import load_system, system_from_dict, system_to_toml


@pytest.fixture(scope="module")
def ball2(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return built_or_skip(build_ball2(tmp_path_factory.mktemp("ball2")))


@pytest.fixture(scope="module")
def ball3(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return built_or_skip(build_ball3(tmp_path_factory.mktemp("ball3")))


def _exact(times: Any) -> tuple[np.ndarray, np.ndarray]:
    pairs = [exact_height(float(t)) for t in times]
    return np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])


def _ball(path: Path, algorithm: str = "jacobi", interface: str | None = None, stop_time: float = 2.0,
          **settings: Any) -> Any:
    return (SystemBuilder("ball").simulation(stop_time=stop_time, step=0.01, algorithm=algorithm, **settings)
            .add_fmu("ball", path, interface=interface).record("ball.h", "ball.count").build())


@pytest.mark.parametrize("algorithm", ["jacobi", "gauss-seidel", "iterative", "gauss-seidel-interpolated"])
def test_a_model_exchange_fmu_is_integrated_to_the_exact_bounces(ball2, algorithm):
    data = run(_ball(ball2, algorithm)).data
    height, bounces = _exact(data["time"])
    assert data["ball.count"].tolist() == bounces.tolist()  # every state event found, none twice
    bound = 2e-5 if algorithm != "iterative" else 2e-3      # the iterative master restarts CVode every step
    assert np.abs(data["ball.h"] - height).max() < bound
    assert data["ball.count"].iloc[-1] == 4  # at 0.45, 1.08, 1.53 and 1.84 s


def test_the_integrator_tolerance_is_the_systems(ball2):
    errors = []
    for tolerance in (1e-4, 1e-6, 1e-8):
        data = run(_ball(ball2, relative_tolerance=tolerance)).data
        errors.append(np.abs(data["ball.h"] - _exact(data["time"])[0]).max())
    assert errors[0] > 10 * errors[1] > 100 * errors[2]


def test_time_events_are_met_exactly(ball2):
    system = (SystemBuilder("late").simulation(stop_time=1.0, step=0.3)
              .add_fmu("ball", ball2, parameters={"tSwitch": 0.45}).record("ball.late").build())
    data = run(system).data
    assert data["ball.late"].tolist() == [False, False, True, True, True]  # 0, 0.3, 0.6, 0.9, 1.0


def test_a_held_continuous_input_drives_the_integrated_fmu(ball2):
    """An upward acceleration equal to gravity: the ball floats where it was let go."""
    system = (SystemBuilder("float").simulation(stop_time=1.0, step=0.05)
              .add_fmu("ball", ball2).add_block("lift", Constant("lift", G)).connect("lift.y", "ball.a")
              .record("ball.h", "ball.v").build())
    data = run(system).data
    np.testing.assert_allclose(data["ball.h"], 1.0, atol=1e-9)
    np.testing.assert_allclose(data["ball.v"], 0.0, atol=1e-9)


def test_an_fmu_ending_the_simulation_in_an_event_ends_the_run_cleanly(ball2):
    """maxBounces = 3: the FMU ends the simulation in the event of the third bounce, at
    t1 + 2 e v1 / g + 2 e^2 v1 / g with t1 = sqrt(2 h0 / g), v1 = g t1; a one-FMU run keeps a last
    row there, as FMPy does."""
    system = (SystemBuilder("three").simulation(stop_time=3.0, step=0.01)
              .add_fmu("ball", ball2, parameters={"maxBounces": 3}).record("ball.count", "ball.h").build())
    result = run(system)
    t1 = math.sqrt(2 * 1.0 / G)
    third = t1 + 2 * E * G * t1 / G + 2 * E * E * G * t1 / G
    assert "ended the simulation" in (result.stopped or "")
    assert result.data["ball.count"].iloc[-1] == 3 and result.data["ball.count"].iloc[-2] == 2
    assert abs(result.data["time"].iloc[-1] - third) < 1e-4 and result.data["ball.h"].iloc[-1] == 0.0


@pytest.mark.parametrize("algorithm", ["jacobi", "gauss-seidel", "iterative", "gauss-seidel-interpolated"])
def test_discrete_inputs_of_a_model_exchange_fmu_are_set_in_event_mode(ball2, tmp_path, algorithm):
    """The ball is frozen (a discrete Boolean input, which the FMU accepts only in Event Mode) from
    0.2 s to 0.3 s while a continuous input is also connected: its height stands still for 0.1 s
    and then falls as the exact ball delayed by 0.1 s. Every master gives the FMU the input at the
    communication point it steps from, and takes the input event at 0.2 s there (FMPy's timing):
    the freeze begins at 0.2 s under each (before issue 44, a step earlier under Gauss-Seidel and
    the iterative master)."""
    signals = tmp_path / "frozen.csv"
    signals.write_text("time,a,frozen\n0,0,false\n0.2,0,false\n0.2,0,true\n0.3,0,true\n0.3,0,false\n1,0,false\n")
    system = (SystemBuilder("frozen").simulation(stop_time=0.5, step=0.01, algorithm=algorithm)
              .add_fmu("ball", ball2)
              .add_block("in", CsvInput("in", signals, hold=["frozen"], types={"frozen": "Boolean"}))
              .connect("in.a", "ball.a").connect("in.frozen", "ball.frozen").record("ball.h").build())
    data = run(system).data
    times = data["time"].to_numpy()
    begin = 0.2
    expected = _exact(np.where(times <= begin, times, np.maximum(times - 0.1, begin)))[0]
    assert np.abs(data["ball.h"].to_numpy() - expected).max() < (2e-5 if algorithm != "iterative" else 2e-4)


def test_fmi3_co_simulation_steps_exactly_and_records_every_scalar_type(ball3):
    system = (SystemBuilder("b3").simulation(stop_time=2.0, step=0.01)
              .add_fmu("ball", ball3, parameters={"label": "moon", "gainU8": 100}).build())
    data = run(system).data
    height, bounces = _exact(data["time"])
    np.testing.assert_allclose(data["ball.h"], height, rtol=0, atol=1e-12)
    assert data["ball.count"].tolist() == bounces.tolist()
    assert str(data["ball.h32"].dtype) == "float32" and str(data["ball.count64"].dtype) == "int64"
    np.testing.assert_allclose(data["ball.h32"], data["ball.h"].astype(np.float32), rtol=0, atol=0)
    assert (data["ball.countU8"] == (100 * data["ball.count"]) % 256).all()   # UInt8 wraps at 256
    assert set(data["ball.tag"]) == {"moon!"}                                  # a String parameter and output


def test_fmi3_model_exchange_agrees_with_its_co_simulation(ball3):
    cs = run(_ball(ball3)).data
    me = run(_ball(ball3, interface="model-exchange")).data
    assert me["ball.count"].tolist() == cs["ball.count"].tolist()
    assert np.abs(me["ball.h"] - cs["ball.h"]).max() < 2e-5


def test_an_fmu_offering_both_interfaces_runs_as_co_simulation_unless_asked(ball3, ball2, tmp_path):
    text = (f'[simulation]\nstop_time = 1.0\nstep = 0.1\n[[fmu]]\nname = "ball"\npath = "{ball3}"\n'
            'interface = "model-exchange"\n')
    (tmp_path / "me.toml").write_text(text)
    system = load_system(tmp_path / "me.toml")
    assert system.fmus[0].interface == "model-exchange"
    assert 'interface = "model-exchange"' in system_to_toml(system)
    assert _ball(ball3).fmus[0].interface == "co-simulation"
    with pytest.raises(SystemFileError, match="'co-simulation': expected one that Ball2.fmu offers: model-exchange"):
        _ball(ball2, interface="co-simulation")
    with pytest.raises(SystemFileError, match="interface: 'cs': expected one of co-simulation, model-exchange"):
        system_from_dict({"simulation": {"stop_time": 1.0, "step": 0.1},
                          "fmu": [{"name": "b", "path": str(ball3), "interface": "cs"}]}, name="x", base=tmp_path)


def test_fmi3_and_fmi2_fmus_connect_across_versions(ball3, typed):
    system = (SystemBuilder("mixed").simulation(stop_time=1.0, step=0.01, algorithm="gauss-seidel")
              .add_fmu("ball", ball3).add_fmu("t", typed)
              .connect("ball.h", "t.u").connect("ball.count", "t.k").connect("ball.late", "t.b")
              .record("ball.h", "t.y", "ball.count", "t.k2", "ball.late", "t.notb").build())
    data = run(system).data
    np.testing.assert_allclose(data["t.y"], 2.0 * data["ball.h"], rtol=0, atol=1e-12)  # Float64 -> Real
    assert (data["t.notb"].to_numpy() == ~data["ball.late"].to_numpy()).all()            # Boolean -> Boolean
    assert (data["t.k2"] - data["ball.count"]).tolist() == list(range(101))             # Int32 -> Integer
    with pytest.raises(SystemFileError, match="ball.h32 is Float32, t.u is Real"):
        SystemBuilder("bad").simulation(stop_time=1.0, step=0.1).add_fmu("ball", ball3).add_fmu("t", typed) \
            .connect("ball.h32", "t.u")


def test_strings_flow_through_connections_and_are_recorded(typed):
    system = (SystemBuilder("strings").simulation(stop_time=0.3, step=0.1, algorithm="gauss-seidel")
              .add_fmu("a", typed, parameters={"label": "A"}, start={"s": "x, \"quoted\""})
              .add_fmu("b", typed, parameters={"label": "B"})
              .connect("a.sout", "b.s").record("a.sout", "b.sout").build())
    data = run(system).data
    assert set(data["a.sout"]) == {'A:x, "quoted"'}
    assert set(data["b.sout"]) == {'B:A:x, "quoted"'}


def test_out_of_range_values_of_the_fmi3_types_are_refused(ball3):
    with pytest.raises(SystemFileError, match="gainU8: 300: expected a whole number from 0 to 255"):
        SystemBuilder("r").add_fmu("ball", ball3, parameters={"gainU8": 300})


def test_rover_cosim_run_takes_a_model_exchange_only_fmu(ball2, tmp_path, capsys):
    out = tmp_path / "ball.csv"
    assert main(["run", str(ball2), "--stop-time", "1.0", "-o", str(out)]) == 0
    text = out.read_text().splitlines()
    assert text[0] == "time,model.h,model.v,model.count,model.late" and len(text) == 102  # frozen: an input
