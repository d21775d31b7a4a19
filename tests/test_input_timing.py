"""Input timing (issue 44): a participant sees an input signal (a source: a csv input, a step, a
ramp) at the communication point it steps from, as FMPy gives an FMU its inputs, under every
master and whatever the Gauss-Seidel order. Checked on own C FMUs whose exact answer is known, an
integrator x' = u (FMI 2.0, tests/fmus/integrator.c) and the bouncing ball's v' = a - g with g = 0
(FMI 3.0, tests/fmus/ball3.c), row for row against FMPy's simulate_fmu on the same FMU and input."""

from __future__ import annotations

from pathlib import Path

import fmpy
import numpy as np
import pytest
from ball_fmus import build_ball3
from c_fmu import built_or_skip
from integrator_fmu import build_integrator

from rover_cosim.orchestrator import SystemBuilder, run
from rover_cosim.orchestrator.blocks import CsvInput, Step

STEP, STOP = 0.1, 1.0
#: t [s], u, k: u steps from 0 to 1 at 0.5 s (a repeated time), k with it (held: an Integer)
STEP_INPUT = [(0.0, 0.0, 0), (0.5, 0.0, 0), (0.5, 1.0, 1), (1.0, 1.0, 1)]
#: u = t, k rising 0 -> 3 (held between the rows)
RAMP_INPUT = [(0.0, 0.0, 0), (1.0, 1.0, 3)]
INPUTS = {"step": STEP_INPUT, "ramp": RAMP_INPUT}
MASTERS = ("gauss-seidel", "jacobi", "iterative", "gauss-seidel-interpolated")


@pytest.fixture(scope="module")
def integrator(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return built_or_skip(build_integrator(tmp_path_factory.mktemp("integrator")))


@pytest.fixture(scope="module")
def ball3(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return built_or_skip(build_ball3(tmp_path_factory.mktemp("ball3")))


def _csv(folder: Path, rows: list[tuple[float, float, int]], names: tuple[str, str] = ("u", "k")) -> Path:
    path = folder / "input.csv"
    path.write_text(f"time,{names[0]},{names[1]}\n" + "".join(f"{t},{u},{k}\n" for t, u, k in rows))
    return path


def _fmpy(fmu: Path, rows: list[tuple[float, float, int]], names: tuple[str, str], interface: str,
          **options: object) -> np.ndarray:
    signals = np.array(rows, dtype=[("time", float), (names[0], float), (names[1], np.int32)])
    return fmpy.simulate_fmu(str(fmu), fmi_type=interface, input=signals, stop_time=STOP, output_interval=STEP,
                             **options)


def _ours(fmu: Path, csv: Path, master: str, interface: str, outputs: tuple[str, ...], order_first: bool = False,
          **starts: float) -> dict[str, np.ndarray]:
    builder = SystemBuilder("input timing").simulation(stop_time=STOP, step=STEP, algorithm=master)
    builder.add_fmu("model", fmu, interface=interface, start=starts or None)
    builder.add_block("input", CsvInput("input", csv, hold=("k",), types={"k": "Integer"}))
    builder.connect("input.u", "model.u").connect("input.k", "model.k")
    builder.record(*[f"model.{name}" for name in outputs], replace=True)
    if order_first:  # the source before the FMU in the Gauss-Seidel order: it still gives its value at t
        builder.simulation(order=["input", "model"])
    data = run(builder.build()).data
    return {"time": data["time"].to_numpy(), **{name: data[f"model.{name}"].to_numpy() for name in outputs}}


@pytest.mark.parametrize("master", MASTERS)
@pytest.mark.parametrize("signal", INPUTS)
def test_an_fmu_steps_from_t_with_the_input_at_t_as_fmpy_gives_it(integrator, tmp_path, master, signal):
    """Co-Simulation, FMI 2.0: x(t_n) = sum of u(t_k) h over the steps before (the input held over
    each step from its value where the step starts), exactly FMPy's rows; the step input of 1 from
    0.5 s gives x(1) = 0.5 exactly, the ramp u = t gives 0.5 - h/2 (first order, as FMPy)."""
    rows = INPUTS[signal]
    ours = _ours(integrator, _csv(tmp_path, rows), master, "co-simulation", ("x", "y", "m"))
    theirs = _fmpy(integrator, rows, ("u", "k"), "CoSimulation")
    np.testing.assert_allclose(ours["time"], theirs["time"], rtol=0, atol=1e-12)
    for name in ("x", "y", "m"):
        np.testing.assert_allclose(ours[name], theirs[name], rtol=1e-12, atol=1e-12, err_msg=name)
    exact = {"step": 0.5, "ramp": 0.5 - STEP / 2}[signal]
    assert ours["x"][-1] == pytest.approx(exact, abs=1e-12)
    before = ours["time"] <= 0.5 + 1e-9
    if signal == "step":  # the row at 0.5 s still has the old input: the step from 0.5 takes the new one
        assert np.all(ours["x"][before] == 0.0) and ours["x"][ours["time"] > 0.55][0] == pytest.approx(STEP)


@pytest.mark.parametrize("master", ("gauss-seidel", "iterative"))
def test_a_source_first_in_the_order_still_gives_its_value_at_t(integrator, tmp_path, master):
    rows = STEP_INPUT
    ours = _ours(integrator, _csv(tmp_path, rows), master, "co-simulation", ("x",), order_first=True)
    theirs = _fmpy(integrator, rows, ("u", "k"), "CoSimulation")
    np.testing.assert_allclose(ours["x"], theirs["x"], rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("master", MASTERS)
def test_an_fmi3_fmu_sees_the_input_at_t_as_fmpy_gives_it(ball3, tmp_path, master):
    """Co-Simulation, FMI 3.0: the ball without gravity, v' = a, driven by a step of a from 0.5 s."""
    rows = [(0.0, 0.0, 0), (0.5, 0.0, 0), (0.5, 2.0, 0), (1.0, 2.0, 0)]
    csv = tmp_path / "a.csv"
    csv.write_text("time,a\n" + "".join(f"{t},{a}\n" for t, a, _ in rows))
    builder = SystemBuilder("ball").simulation(stop_time=STOP, step=STEP, algorithm=master)
    builder.add_fmu("model", ball3, interface="co-simulation")
    builder.set_parameters("model", {"g": 0.0})
    builder.add_block("input", CsvInput("input", csv)).connect("input.a", "model.a").record("model.v", replace=True)
    ours = run(builder.build()).data["model.v"].to_numpy()
    signals = np.array([(t, a) for t, a, _ in rows], dtype=[("time", float), ("a", float)])
    theirs = fmpy.simulate_fmu(str(ball3), fmi_type="CoSimulation", input=signals, stop_time=STOP,
                               output_interval=STEP, start_values={"g": 0.0})["v"]
    np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=1e-12)
    assert ours[-1] == pytest.approx(2.0 * 0.5, abs=1e-12)


def test_a_step_block_under_gauss_seidel_is_seen_at_t(integrator):
    """The built-in sources follow the same convention as the csv input: a step of u at 0.5 s."""
    builder = SystemBuilder("step").simulation(stop_time=STOP, step=STEP, algorithm="gauss-seidel")
    builder.add_fmu("model", integrator, interface="co-simulation")
    builder.add_block("u", Step("u", 1.0, time=0.5)).connect("u.y", "model.u").record("model.x", replace=True)
    x = run(builder.build()).data["model.x"].to_numpy()
    assert x[-1] == pytest.approx(0.5, abs=1e-12) and x[5] == 0.0


def _last_row_per_time(result: np.ndarray) -> np.ndarray:
    """FMPy's Model Exchange rows with one row per time: the last (after an event at that time)."""
    times = result["time"]
    keep = np.append(np.diff(times) > 1e-12, True)  # an event may repeat its time to the last bit or so
    return result[keep]


def _model_exchange_as_fmpy(integrator: Path, folder: Path, master: str, rows: list[tuple[float, float, int]],
                            exact: tuple[str, ...]) -> dict[str, np.ndarray]:
    """Our Model Exchange run of ``rows`` against FMPy's (its last row per time): the same times, the
    ``exact`` outputs equal, x to CVode's tolerance; ours."""
    ours = _ours(integrator, _csv(folder, rows), master, "model-exchange", ("x", *exact))
    theirs = _last_row_per_time(_fmpy(integrator, rows, ("u", "k"), "ModelExchange"))
    np.testing.assert_allclose(ours["time"], theirs["time"], rtol=0, atol=1e-12)
    for name in exact:
        np.testing.assert_array_equal(ours[name], theirs[name], err_msg=name)
    np.testing.assert_allclose(ours["x"], theirs["x"], rtol=1e-6, atol=1e-9)
    return ours


@pytest.mark.parametrize("master", MASTERS)
def test_model_exchange_takes_an_input_event_at_its_time_and_records_the_new_value(integrator, tmp_path, master):
    """Model Exchange, FMI 2.0: the step of u and k at 0.5 s is an event there; the row at 0.5 s
    shows the new values (y = u = 1, m = k = 1, x still 0), as FMPy's last row at that time; every
    row equals FMPy's to CVode's tolerance."""
    ours = _model_exchange_as_fmpy(integrator, tmp_path, master, STEP_INPUT, ("y", "m"))
    at = int(np.argmin(np.abs(ours["time"] - 0.5)))
    assert (ours["x"][at], ours["y"][at], ours["m"][at]) == (0.0, 1.0, 1)
    assert ours["x"][-1] == pytest.approx(0.5, abs=1e-9)


@pytest.mark.parametrize("master", MASTERS)
def test_a_jump_of_a_continuous_input_is_an_event_as_fmpy_takes_it(integrator, tmp_path, master):
    """Model Exchange, FMI 2.0: u alone jumps from 0 to 1 at 0.5 s (k unchanged). FMPy takes the jump
    as an input event: its event iteration lets the relay r (discrete, set at events only, with an
    event indicator u - 0.5) follow at once. So do we: the row at 0.5 s shows r = 1, every row equals
    FMPy's (an importer that set u in Continuous-Time Mode would leave r at 0: found on MapleSim's
    CoupledClutches, 0.9 % off)."""
    rows = [(0.0, 0.0, 0), (0.5, 0.0, 0), (0.5, 1.0, 0), (1.0, 1.0, 0)]
    ours = _model_exchange_as_fmpy(integrator, tmp_path, master, rows, ("y", "r"))
    at = int(np.argmin(np.abs(ours["time"] - 0.5)))
    assert (ours["r"][at - 1], ours["r"][at]) == (0.0, 1.0)


@pytest.mark.parametrize("interface", ("co-simulation", "model-exchange"))
def test_a_ramp_is_held_over_each_step_from_its_value_at_t(integrator, tmp_path, interface):
    """u = t: x(t_n) = sum of t_k h, 0.45 at 1 s for h = 0.1 (the first-order answer of an input held
    over the step), Co-Simulation exactly and Model Exchange to CVode's tolerance; the discrete k
    (held from row to row) changes at 1 s, where Model Exchange records the new value. (FMPy's Model
    Exchange gives 0.4426 here: it sets the inputs after CVode has stepped past the output point.)"""
    ours = _ours(integrator, _csv(tmp_path, RAMP_INPUT), "gauss-seidel", interface, ("x", "m"))
    expected = np.array([sum(0.1 * k * STEP for k in range(n)) for n in range(11)])
    np.testing.assert_allclose(ours["x"], expected, rtol=1e-6, atol=1e-9)
    assert ours["m"][-2] == 0 and ours["m"][-1] == (3 if interface == "model-exchange" else 0)


def test_fmi3_model_exchange_takes_the_input_event_as_fmpy(ball3, tmp_path):
    rows = [(0.0, 0.0), (0.5, 0.0), (0.5, 2.0), (1.0, 2.0)]
    csv = tmp_path / "a.csv"
    csv.write_text("time,a\n" + "".join(f"{t},{a}\n" for t, a in rows))
    builder = SystemBuilder("ball").simulation(stop_time=STOP, step=STEP, algorithm="gauss-seidel")
    builder.add_fmu("model", ball3, interface="model-exchange")
    builder.set_parameters("model", {"g": 0.0})
    builder.add_block("input", CsvInput("input", csv)).connect("input.a", "model.a").record("model.v", replace=True)
    ours = run(builder.build()).data["model.v"].to_numpy()
    signals = np.array(rows, dtype=[("time", float), ("a", float)])
    theirs = _last_row_per_time(fmpy.simulate_fmu(str(ball3), fmi_type="ModelExchange", input=signals, stop_time=STOP,
                                                  output_interval=STEP, start_values={"g": 0.0}))["v"]
    np.testing.assert_allclose(ours, theirs, rtol=1e-6, atol=1e-9)
    assert ours[-1] == pytest.approx(1.0, abs=1e-9)


def test_the_sources_name_where_they_jump(tmp_path):
    """The times a Model Exchange FMU takes as input events: a csv input's and a table's repeated
    times, a step's time (none for a step of height 0)."""
    from rover_cosim.orchestrator.blocks import Table

    csv = _csv(tmp_path, [(0.0, 0.0, 0), (0.5, 0.0, 0), (0.5, 1.0, 0), (0.8, 1.0, 0), (0.8, 2.0, 0)])
    assert CsvInput("input", csv).jump_times.tolist() == [0.5, 0.8]
    assert Table("t", [0.0, 0.5, 0.5, 1.0], [0.0, 0.0, 1.0, 1.0]).jump_times.tolist() == [0.5]
    assert Step("s", 1.0, 0.3).jump_times.tolist() == [0.3] and Step("s", 0.0, 0.3).jump_times.size == 0
