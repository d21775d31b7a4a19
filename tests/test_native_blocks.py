"""Blocks stepped by the native stepper (orchestrator.native.NativeBlock): the closed-loop
controller's C twin (control/inverse_controller.c) gives the Python block's outputs bit for bit,
alone on random inputs and in the paper's closed loop on both plants, and so does the path controller's
(control/path_controller.c) on the steerable rover; failures are named as
the Python block's; without a compiler the block steps in Python."""

from __future__ import annotations

import ctypes
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest
from scipy.linalg import expm

from rover_cosim.control.controller import InverseModelController
from rover_cosim.control.path_controller import PathFollowingController
from rover_cosim.jobs.simulate import cosim_system, monolithic_system
from rover_cosim.orchestrator import native
from rover_cosim.orchestrator.builder import replace_settings
from rover_cosim.orchestrator.master import RunError, make_master, participants_of, run
from rover_cosim.orchestrator.model import System
from rover_cosim.orchestrator.participants import BlockParticipant
from rover_cosim.orchestrator.wiring import wire

pytestmark = pytest.mark.skipif(native.unavailable_reason() is not None,
                                reason=str(native.unavailable_reason()))


@pytest.fixture(scope="module")
def model(identified, results_root) -> Path:
    return results_root / "identification" / "model.json"


class Twin:
    """The C twin of a block (its functions ``<prefix>_...``), called as the stepper calls it."""

    def __init__(self, block: InverseModelController | PathFollowingController, prefix: str = "controller"):
        made = block.native()
        assert made is not None
        self.made, self.library, self.prefix = made, made.library, prefix
        pointer = ctypes.c_void_p
        for name in ("set_real", "get_real"):
            getattr(self.library, f"{prefix}_{name}").argtypes = [pointer, pointer, ctypes.c_size_t, pointer]
        getattr(self.library, f"{prefix}_do_step").argtypes = [pointer, ctypes.c_double, ctypes.c_double, ctypes.c_int]
        self.inputs = (ctypes.c_uint * len(block.inputs))(*range(len(block.inputs)))
        self.outputs = (ctypes.c_uint * len(block.outputs))(*range(len(block.outputs)))
        self.values = np.zeros(len(block.outputs))

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        u = np.ascontiguousarray(u, dtype=float)
        def call(name: str, *args: object) -> int:
            return int(getattr(self.library, f"{self.prefix}_{name}")(self.made.component, *args))

        call("set_real", self.inputs, u.size, u.ctypes.data)
        if call("do_step", t, h, 1) != 0:
            raise ValueError(self.made.message())
        call("get_real", self.outputs, self.values.size, self.values.ctypes.data)
        return self.values.copy()


def random_inputs(rng: np.random.Generator) -> np.ndarray:
    """x [m], v [m/s] (inside and beyond the saturation of the demand), six loads [N] across the
    table and beyond it."""
    return np.array([rng.uniform(-2.0, 40.0), rng.uniform(-1.0, 2.0), *rng.uniform(50.0, 1200.0, 6)])


@pytest.mark.parametrize("options", [{}, {"model_label": "linear"}, {"fixed_load": 424.0}],
                         ids=["quadratic model", "linear model", "fixed load"])
def test_the_c_twin_gives_the_python_blocks_outputs_bit_for_bit(model, options):
    rng = np.random.default_rng(18)
    block = InverseModelController("ctrl", str(model), **options)
    block.start(0.0, random_inputs(rng))
    twin = Twin(block)
    steps = [1e-3] * 3000 + [4e-4, 1e-3 * (1 + 1e-10), 1e-3]  # a shorter step, one within the allowance
    t = 0.0
    for k, h in enumerate(steps):
        u = random_inputs(rng)
        expected, got = block.step(t, h, u), twin.step(t, h, u)
        assert np.array_equal(expected, got), f"step {k}: {expected - got}"
        t += h
    twin.made.close()


def test_a_wheel_off_the_ground_gets_no_torque_and_the_twin_agrees(model):
    """A wheel under 1 N or less (a leg-wheel rover's lifted wheel; the FMUs' floor is 1 mN) gets
    no torque and its filter rests, in Python and in C alike, bit for bit; the other wheels are
    driven as ever, and set down again the wheel is driven from rest."""
    from rover_cosim.control.longitudinal import NO_LOAD

    block = InverseModelController("ctrl", str(model))
    u = np.array([0.0, 0.5, *[424.0] * 6])
    block.start(0.0, u)
    twin = Twin(block)
    t = 0.0
    for k in range(600):
        u[2] = 0.001 if 100 <= k < 400 else 424.0  # wheel 1 in the air from step 100 to 399
        expected, got = block.step(t, 1e-3, u), twin.step(t, 1e-3, u)
        assert np.array_equal(expected, got), f"step {k}: {expected - got}"
        if 100 <= k < 400:
            assert expected[0] == 0.0 and expected[1] == expected[2] != 0.0
        t += 1e-3
    assert 0.0 < expected[0] < 2 * expected[1] and NO_LOAD == 1.0
    twin.made.close()


def test_a_light_wheel_gets_the_lightest_loads_torque_scaled_by_its_load_and_the_twin_agrees(model):
    """Between 1 N and the tables' lightest load the law does not extrapolate its torque tables in
    1/W nor its Fx model (which turned the torque over: 26 N asked at 30 N gave -5.1 N·m): a wheel
    at k times that load gets k times the lightest load's torque for the same force (to round-off):
    continuous there, 0 towards no load, never turned over; a wheel lifting off through those loads
    and set down again gets the same torques in Python and in C."""
    block = InverseModelController("ctrl", str(model))
    inverse = block.inverse
    lightest = 1.0 / inverse.tables()[0][0]
    assert lightest > 10.0
    for force in (1.0, 26.0, 100.0):
        for k in (0.999999, 0.5, 0.3, 0.1, 0.02):
            load = k * lightest
            light = inverse.torques(np.array([load]), np.array([force]), advance=False)[0]
            at_lightest = inverse.torques(np.array([lightest]), np.array([force]), advance=False)[0]
            assert light == pytest.approx(k * at_lightest, rel=1e-12), (force, k)
            assert light > 0, (force, k)
    u = np.array([0.0, 0.5, *[424.0] * 6])
    block.start(0.0, u)
    twin = Twin(block)
    t = 0.0
    for k in range(500):  # wheel 1 unloads over 0.1 s, 0.1 s in the air, loaded again over 0.1 s
        u[2] = max(424.0 * min(abs(k - 250) - 50, 100) / 100, 0.001)
        expected, got = block.step(t, 1e-3, u), twin.step(t, 1e-3, u)
        assert np.array_equal(expected, got), f"step {k}: {expected - got}"
        if u[2] < lightest:  # asked the loaded wheels' pull: driven ahead, never turned over
            assert expected[0] >= 0.0
        t += 1e-3
    twin.made.close()


def test_the_c_twin_refuses_what_the_python_block_refuses(model):
    block = InverseModelController("ctrl", str(model))
    u = np.array([0.0, 0.0, *[424.0] * 6])
    block.start(0.0, u)
    twin = Twin(block)
    with pytest.raises(ValueError, match=r"communication step 0.002 s: expected at most its step = 0.001 s"):
        twin.step(0.0, 2e-3, u)
    with pytest.raises(ValueError, match=r"loads = -5 N: expected > 0"):
        twin.step(0.0, 1e-3, np.array([0.0, 0.0, 424.0, -5.0, *[424.0] * 4]))
    twin.made.close()


def test_the_filter_is_discretised_exactly(model):
    """The closed form of the critically damped filter against scipy's matrix exponential."""
    inverse = InverseModelController("ctrl", str(model)).inverse
    wn = inverse.wn
    a, b = np.array([[0.0, 1.0], [-wn * wn, -2.0 * wn]]), np.array([0.0, wn * wn])
    for step in (1e-5, 1e-3, 2.5e-2):  # wn h up to 8.6
        ad, bd = inverse.discretised(step)
        exact = expm(a * step)
        np.testing.assert_allclose(ad, exact, rtol=1e-12, atol=1e-12 * np.abs(exact).max())
        np.testing.assert_allclose(bd, np.linalg.solve(a, (exact - np.eye(2)) @ b), rtol=1e-10, atol=1e-13)


def short(system: System, stop_time: float, **simulation: Any) -> System:
    return replace_settings(system, stop_time=stop_time, **simulation)


def assert_native_is_python(system: Any) -> None:
    """``system(native)``, a system stepped natively or not: natively every participant is stepped
    by the native stepper, and the recorded frames equal those stepped in Python, exactly."""
    python = run(system(False))
    ours = system(True)
    wiring = wire(ours)
    with participants_of(ours, wiring) as participants:
        master = make_master(ours, participants, wiring)
        assert master.all_native
        master.close()
    pd.testing.assert_frame_equal(python.data, run(ours).data, check_exact=True)


@pytest.mark.parametrize("algorithm", ["gauss-seidel", "jacobi"])
@pytest.mark.parametrize("plant", [monolithic_system, cosim_system], ids=["Rover.fmu", "co-simulated"])
def test_the_closed_loop_with_the_c_twin_is_the_python_closed_loop(fmu_dir, model, plant, algorithm):
    def system(native_stepping: bool) -> System:
        return short(plant(fmu_dir, model), 0.4, algorithm=algorithm, native=native_stepping)

    assert_native_is_python(system)  # the controller is stepped by the stepper as well


def test_a_failing_c_twin_is_named_with_its_message(fmu_dir, model):
    """Limb 1's load falls to 0 N at 0.5 ms (a step source in place of the rover's Fz[1]; the
    controller sees it from the next communication point, 1 ms, on): the controller's C twin
    refuses it, and the run names the block, the call, the time and why."""
    from rover_cosim.orchestrator.blocks import Step
    from rover_cosim.orchestrator.builder import SystemBuilder

    builder = SystemBuilder("a load that vanishes").simulation(stop_time=0.1, step=1e-3)
    builder.add_fmu("rover", fmu_dir / "Rover.fmu")
    builder.add_block("load1", Step("load1", -424.0, time=5e-4, offset=424.0, unit="N"))
    builder.add_block("ctrl", InverseModelController("ctrl", str(model)))
    builder.connect("rover.x", "ctrl.x").connect("rover.v", "ctrl.v").connect("load1.y", "ctrl.W[1]")
    for i in range(1, 7):
        if i > 1:
            builder.connect(f"rover.Fz[{i}]", f"ctrl.W[{i}]")
        builder.connect(f"ctrl.tau[{i}]", f"rover.tau[{i}]")
    with pytest.raises(RunError, match=r"ctrl \(block\): step at t = 0.001 s failed: loads = 0 N: expected > 0") \
            as info:
        run(builder.build())
    assert len(info.value.partial) == 2  # the start and the first step


def test_without_a_compiler_the_controller_steps_in_python(fmu_dir, model, tmp_path, monkeypatch):
    monkeypatch.setenv("ROVER_COSIM_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("CC", str(tmp_path / "no-such-compiler"))
    native.load_library.cache_clear()  # the stepper stays loaded; the controller's source is new to the cache
    try:
        assert InverseModelController("ctrl", str(model)).native() is None
        system = short(monolithic_system(fmu_dir, model), 0.05)
        wiring = wire(system)
        with participants_of(system, wiring) as participants:
            master = make_master(system, participants, wiring)
            ctrl = next(p for p in participants if isinstance(p, BlockParticipant))
            assert master.stepper is not None and participants.index(ctrl) not in master.natively
            master.close()
        assert len(run(system).data) == 51
    finally:
        monkeypatch.undo()
        native.load_library.cache_clear()


# --- the path-following controller's C twin (path_controller.c) -----------------------------------

def near_the_path(block: PathFollowingController, s: float, rng: np.random.Generator) -> np.ndarray:
    """Inputs of a rover near arc length ``s`` of the block's path: off it by centimetres, its
    heading by degrees, speed, loads and slip angles spread (some loads below the 1 N floor)."""
    x, y, heading, _ = (float(v) for v in block.path.at(s))
    return np.array([x + rng.normal(0, 0.05), y + rng.normal(0, 0.05), heading + rng.normal(0, 0.05),
                     0.5 + rng.normal(0, 0.2), rng.normal(0, 0.02), rng.normal(0, 0.05),
                     *rng.uniform(-20.0, 900.0, block.wheels), *rng.normal(0, 0.08, block.wheels)])


@pytest.mark.parametrize("x_limb", [(0.64, -0.64), (1.2, 0.4, -0.4, -1.2)], ids=["4 wheels", "8 wheels"])
def test_the_path_controllers_c_twin_follows_any_number_of_wheels(model, x_limb):
    """A rover of another number of wheels (a VIPER-class four, an eight): the twin still gives the
    Python block's outputs bit for bit, and both allocate the demand over every wheel."""
    rng = np.random.default_rng(46)
    block = PathFollowingController("ctrl", str(model), path="turn", x_limb=x_limb, y_limb=0.61, mass=430.0,
                                    yaw_inertia=161.3)
    assert block.wheels == 2 * len(x_limb) and len(block.outputs) == 4 * block.wheels + 4
    twin_follows_the_block(block, rng, 400, f"{block.wheels} wheels")


def twin_follows_the_block(block: PathFollowingController, rng: np.random.Generator, steps: int, label: str) -> None:
    """``steps`` steps of 1 ms near the block's path: its C twin's outputs equal the block's bit for bit."""
    block.start(0.0, near_the_path(block, 0.0, rng))
    twin = Twin(block, "path")
    t = 0.0
    for k in range(1, steps):
        u = near_the_path(block, 0.01 * k, rng)
        expected, got = block.step(t, 1e-3, u), twin.step(t, 1e-3, u)
        assert np.array_equal(expected, got), f"{label}, step {k}: outputs {np.flatnonzero(expected != got)} differ"
        t += 1e-3
    twin.made.close()


@pytest.mark.parametrize("path", ["turn", "lane_change"])
@pytest.mark.parametrize("steering", ["inverse", "kinematic"])
def test_the_path_controllers_c_twin_gives_the_python_blocks_outputs_bit_for_bit(model, steering, path):
    rng = np.random.default_rng(34)
    block = PathFollowingController("ctrl", str(model), path=path, steering=steering)
    block.start(0.0, near_the_path(block, 0.0, rng))
    twin = Twin(block, "path")
    t = 0.0
    for k in range(1, 2500):
        h = 4e-4 if k == 1200 else 1e-3  # one shorter step: the filter discretised for it
        u = near_the_path(block, 0.01 * k, rng)  # 10 m/s along the path: the search window moves on
        expected, got = block.step(t, h, u), twin.step(t, h, u)
        assert np.array_equal(expected, got), f"step {k}: outputs {np.flatnonzero(expected != got)} differ"
        t += h
    with pytest.raises(ValueError, match=r"communication step 0.002 s: expected at most its step = 0.001 s"):
        twin.step(t, 2e-3, u)
    twin.made.close()


@pytest.mark.parametrize("plant", ["monolithic", "cosim"])
def test_path_following_with_the_c_twin_is_the_python_path_following(fmu_dir, model, plant):
    from rover_cosim.jobs import path_following

    def system(native_stepping: bool) -> System:
        made = (path_following.monolithic_system(fmu_dir, model, "lane_change", straight=1.0) if plant == "monolithic"
                else path_following.cosim_system(fmu_dir, model, "lane_change", straight=1.0))
        return short(made, 0.3, native=native_stepping)

    assert_native_is_python(system)  # the path controller is stepped by the stepper as well


def test_a_change_of_an_included_header_compiles_the_twin_again(tmp_path, monkeypatch):
    """The cache's digest covers the headers a twin includes (inverse_law.h, the maps' laws from
    the folder beside its own, and the header those include): an edited law is never served from
    a library built before the edit."""
    from rover_cosim.control import path_controller

    monkeypatch.setenv("ROVER_COSIM_CACHE", str(tmp_path / "cache"))
    source = tmp_path / "twin.c"
    source.write_text('#include "law.h"\nint twin_value(void) { return VALUE; }\n')
    (tmp_path / "law.h").write_text('#include "deeper.h"\n')
    (tmp_path / "deeper.h").write_text("#define VALUE 1\n")
    headers = [path.resolve() for path in native.local_headers(path_controller.C_SOURCE)]
    laws = path_controller.C_SOURCE.parent.parent / "terramechanics"
    assert headers == [path_controller.C_SOURCE.with_name("inverse_law.h").resolve(),
                       (laws / "height_map.h").resolve(), (laws / "soil_map.h").resolve(),
                       (laws / "grid_search.h").resolve()]  # included by the two maps' headers
    native.load_library.cache_clear()
    try:
        first = native.load_library(source, ("twin_value",))
        assert not isinstance(first, str) and first.twin_value() == 1
        (tmp_path / "deeper.h").write_text("#define VALUE 2\n")  # a header the included one includes
        native.load_library.cache_clear()
        second = native.load_library(source, ("twin_value",))
        assert not isinstance(second, str) and second.twin_value() == 2
        assert len(list((tmp_path / "cache").glob("twin-*.so"))) == 2
    finally:
        native.load_library.cache_clear()


class _LateWithoutTwin:
    """A torque source that says it is ready for the native stepper after 0.05 s but then has no
    C twin: the engine asks it once more, and it steps in Python to the end."""

    name = "late"
    inputs: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ("y",)
    units = {"y": "N.m"}

    def __init__(self) -> None:
        self.t, self.asked = 0.0, 0

    def start(self, t0: float, u0: np.ndarray, h: float) -> np.ndarray:
        return np.array([20.0])

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        self.t = t + h
        return np.array([20.0])

    def native_ready(self) -> bool:
        return self.t >= 0.05

    def native(self) -> None:
        self.asked += 1
        return None


def test_a_block_ready_for_a_twin_it_then_lacks_is_asked_once_and_steps_on_in_python(fmu_dir, monkeypatch):
    from rover_cosim.orchestrator import master
    from rover_cosim.orchestrator.builder import SystemBuilder

    handovers: list[int] = []
    original = master._handed_over

    def counted(*args: Any) -> Any:
        handovers.append(1)
        return original(*args)

    monkeypatch.setattr(master, "_handed_over", counted)
    block = _LateWithoutTwin()
    builder = SystemBuilder("late").simulation(stop_time=0.2, step=1e-3, algorithm="gauss-seidel")
    builder.add_fmu("wheel", fmu_dir / "Wheel.fmu", start={"W": 424.0, "v_hub": 0.0})
    builder.add_block("late", block).connect("late.y", "wheel.tau")
    result = run(builder.build())
    assert len(result.data) == 201 and result.steps == 200
    assert block.asked == 2 and handovers == [1]  # at the start, and once when it said it was ready
    assert result.step_seconds["late"] > 0  # stepped in Python to the end


@pytest.mark.parametrize("steering", ["inverse", "kinematic"])
def test_the_twin_takes_the_planes_pull_as_the_terrain_controller_does(model, steering):
    """On a 20° side slope (and a diagonal one) the terrain controller's feed-forward of gravity's
    pull is in the twin too: outputs bit for bit; over a map other than a HeightMap it offers no twin."""
    from rover_cosim.control.terrain_controller import TerrainPathController
    from rover_cosim.terramechanics import PlaneTerrain

    rng = np.random.default_rng(35)
    for terrain in (PlaneTerrain.side_slope(20.0), PlaneTerrain(0.3, 2.5)):
        block = TerrainPathController("ctrl", str(model), path="lane_change", steering=steering, terrain=terrain)
        twin_follows_the_block(block, rng, 1500, terrain.label())

    class Bowl:
        def gradient(self, x: Any, y: Any) -> tuple[Any, Any]:
            return 0.01 * np.asarray(x), 0.01 * np.asarray(y)

    assert TerrainPathController("ctrl", str(model), ground_map=Bowl()).native() is None  # a map it cannot copy


# --- the soil map's twins (terramechanics/soil_map.h) -------------------------------------------------

def _soil_maps() -> list[Any]:
    """A straight boundary, and a grid of random shares on unevenly spaced lines."""
    from rover_cosim.terramechanics import Soil
    from rover_cosim.terramechanics.library import choose
    from rover_cosim.terramechanics.terrain import SoilMap, soil_boundary

    soft = choose(soil="hit_lss1").soil
    rng = np.random.default_rng(35)
    uneven = SoilMap(np.linspace(-3, 9, 13) ** 3 / 30, np.linspace(-4, 4, 9) ** 3 / 16, rng.uniform(0, 1, (9, 13)),
                     Soil(), soft)
    return [soil_boundary(5.0, Soil(), soft, width=2.0), uneven]


def test_the_soil_participants_twin_gives_its_shares_bit_for_bit():
    """Random poses on and beyond the grids (and a NaN pose): the same shares as the Python block."""
    from rover_cosim.jobs.ground import SoilBlock

    rng = np.random.default_rng(36)
    for soil_map in _soil_maps():
        block = SoilBlock("soil", soil_map)
        block.start(0.0, np.array([0.0, 0.0, 0.0]))
        twin = Twin(block, "soil")  # type: ignore[arg-type]
        poses = np.column_stack([rng.uniform(-12, 40, 5000), rng.uniform(-8, 8, 5000), rng.uniform(-4, 4, 5000)])
        for k, u in enumerate([*poses, np.array([np.nan, 0.0, 0.0])]):
            expected, got = block.step(0.0, 1e-3, u), twin.step(0.0, 1e-3, u)
            assert np.array_equal(expected, got, equal_nan=True), f"{soil_map.source}, pose {k}: {expected} {got}"
        twin.made.close()


@pytest.mark.parametrize("steering", ["inverse", "kinematic"])
def test_the_twin_believes_a_soil_map_as_the_terrain_controller_does(model, steering):
    """A controller that believes a soil map (the models of both soils blended under each wheel)
    on a side slope: its twin's outputs bit for bit, across the boundary and on a random grid."""
    from test_soil_map import _other_models

    from rover_cosim.control.terrain_controller import TerrainPathController
    from rover_cosim.identification.model_set import ModelSet
    from rover_cosim.terramechanics import PlaneTerrain

    models = ModelSet.read(model)
    rng = np.random.default_rng(37)
    for boundary, soil_map in zip((True, False), _soil_maps()):
        block = TerrainPathController("ctrl", models, path="lane_change", steering=steering,
                                      terrain=PlaneTerrain.side_slope(10.0), soil_map=soil_map,
                                      model_b=_other_models(models))
        block.start(0.0, near_the_path(block, 0.0, rng))
        twin = Twin(block, "path")
        t, shares = 0.0, set()
        for k in range(1, 1500):
            u = near_the_path(block, 0.01 * k, rng)
            expected, got = block.step(t, 1e-3, u), twin.step(t, 1e-3, u)
            assert np.array_equal(expected, got), f"{soil_map.source}, step {k}: outputs differ"
            shares.update(block.shares)
            t += 1e-3
        assert len(shares) > 100 and (not boundary or {0.0, 1.0} <= shares)  # each soil and the blends met
        twin.made.close()


@pytest.mark.parametrize("plant", ["inverse", "cosim"])
def test_the_soil_crossing_with_the_twins_is_the_python_soil_crossing(fmu_dir, model, plant):
    """The soil crossing's system (the controller believing the map, the soil participant) stepped
    by the native stepper: every participant native, the recorded frames equal to Python's."""
    from test_soil_map import PAPER, _other_models

    from rover_cosim.identification.model_set import ModelSet
    from rover_cosim.jobs.terrain import soil_map_of, traverse_system
    from rover_cosim.terramechanics import PlaneTerrain

    models = ModelSet.read(model)

    def system(native_stepping: bool) -> System:
        made = traverse_system(fmu_dir, models, PlaneTerrain.side_slope(10.0), plant, length=3.0,
                               soil_map=soil_map_of(PAPER, replace_crossing(boundary=1.5)),
                               model_b=_other_models(models))
        return short(made, 0.3, native=native_stepping)

    assert_native_is_python(system)  # the controller and the soil participant too


def replace_crossing(**changes: Any) -> Any:
    from dataclasses import replace

    from rover_cosim.jobs.terrain import SOIL_CROSSING

    return replace(SOIL_CROSSING, **changes)



# --- the height map's twins (terramechanics/height_map.h) ---------------------------------------------

def _height_maps() -> list[Any]:
    """The crater of the scenario, a bowl with a rim, and a random map on unevenly spaced lines."""
    from rover_cosim.terramechanics.terrain import HeightMap, crater

    rng = np.random.default_rng(38)
    uneven = HeightMap(np.sort(rng.uniform(-8, 20, 12)), np.sort(rng.uniform(-8, 8, 9)), rng.normal(0, 0.05, (9, 12)))
    return [crater((10.0, -2.5), 0.12, 4.0, rim=0.0), crater((6.0, 1.0), 0.2, 2.0, rim=0.1, spacing=0.3), uneven]


def test_the_height_maps_spline_is_fitpacks():
    """HeightMap evaluates its spline itself (the twins' arithmetic): the height and gradient of
    scipy's RectBivariateSpline (FITPACK) within 1e-13 of their largest values (measured 5e-15
    relative); at the grid points its heights."""
    from scipy.interpolate import RectBivariateSpline

    rng = np.random.default_rng(39)
    for height_map in _height_maps():
        theirs = RectBivariateSpline(height_map.y, height_map.x, height_map.heights, kx=3, ky=3)
        x = rng.uniform(height_map.x[0], height_map.x[-1], 2000)
        y = rng.uniform(height_map.y[0], height_map.y[-1], 2000)
        gx, gy = height_map.gradient(x, y)
        for ours, expected in ((height_map.height(x, y), theirs.ev(y, x)), (gx, theirs.ev(y, x, dy=1)),
                               (gy, theirs.ev(y, x, dx=1))):
            np.testing.assert_allclose(ours, expected, rtol=0, atol=1e-13 * np.abs(expected).max())
        gx_grid, gy_grid = np.meshgrid(height_map.x, height_map.y)
        np.testing.assert_allclose(height_map.height(gx_grid, gy_grid), height_map.heights, rtol=0, atol=1e-14)


def test_the_ground_participants_twin_gives_its_outputs_bit_for_bit():
    """Random poses and velocities on and beyond the maps (and a NaN pose): the same heights, rates
    and gradients as the Python block."""
    from rover_cosim.jobs.ground import GroundBlock

    rng = np.random.default_rng(40)
    for height_map in _height_maps():
        block = GroundBlock("ground", height_map)
        block.start(0.0, np.zeros(6))
        twin = Twin(block, "ground")  # type: ignore[arg-type]
        for k in range(300):
            u = np.array([rng.uniform(-25, 35), rng.uniform(-25, 20), rng.uniform(-4, 4), rng.normal(0.5, 0.5),
                          rng.normal(0, 0.1), rng.normal(0, 0.2)])
            if k == 299:
                u[0] = np.nan
            expected, got = block.step(0.0, 1e-3, u), twin.step(0.0, 1e-3, u)
            assert np.array_equal(expected, got, equal_nan=True), f"{height_map.source}, pose {k}"
        twin.made.close()


@pytest.mark.parametrize("steering", ["inverse", "kinematic"])
def test_the_twin_feeds_the_height_maps_pull_forward_as_the_terrain_controller_does(model, steering):
    """Over the maps (on level ground and on a 10° side slope) the controller's feed-forward of the
    loads' pull on the map's slopes is in the twin too: outputs bit for bit."""
    from rover_cosim.control.terrain_controller import TerrainPathController
    from rover_cosim.terramechanics import PlaneTerrain

    rng = np.random.default_rng(41)
    for height_map, terrain in zip(_height_maps(), (None, PlaneTerrain.side_slope(10.0), None)):
        block = TerrainPathController("ctrl", str(model), path="lane_change", steering=steering, terrain=terrain,
                                      ground_map=height_map)
        block.start(0.0, near_the_path(block, 0.0, rng))
        twin = Twin(block, "path")
        t = 0.0
        for k in range(1, 1200):
            u = near_the_path(block, 0.01 * k, rng)
            expected, got = block.step(t, 1e-3, u), twin.step(t, 1e-3, u)
            assert np.array_equal(expected, got), f"{height_map.source}, step {k}: outputs differ"
            t += 1e-3
        twin.made.close()


@pytest.mark.parametrize("plant", ["inverse", "cosim"])
def test_the_crater_with_the_twins_is_the_python_crater(fmu_dir, model, plant):
    """The crater scenario's system (the map's pull fed forward, the ground participant) stepped by
    the native stepper: every participant native, the recorded frames equal to Python's."""
    from rover_cosim.jobs.terrain import CraterScenario, crater_map, traverse_system
    from rover_cosim.terramechanics import PlaneTerrain

    height_map = crater_map(CraterScenario(centre=(4.0, -3.5), depth=0.04, radius=2.5))

    def system(native_stepping: bool) -> System:
        made = traverse_system(fmu_dir, model, PlaneTerrain(), plant, length=3.0, speed=1.0, height_map=height_map)
        return short(made, 0.3, native=native_stepping)

    assert_native_is_python(system)  # the controller and the ground participant too
