"""The Modelica source through rumoca (the Modelica compiler on PyPI, pinned in pyproject.toml):
every model flattens balanced, every example simulates, the UsersGuide documents every FMU's
interface and its Python examples run, and rumoca's simulation agrees with the numpy reference
wheel and between the monolithic and the reconnected rover."""

from __future__ import annotations

import html
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from modelica_defaults import FMU_NODES

from rover_cosim.fmubuild import build, source
from rover_cosim.fmubuild.source import MODELICA_ROOT, PACKAGE
from rover_cosim.terramechanics import Wheel, contact_forces, slip_ratio, wheel_forces, wheel_state

REPOSITORY = Path(__file__).resolve().parents[1]

rumoca = pytest.importorskip("rumoca", reason="rumoca is a pinned dependency; install the project with `make venv`")

MODELS = ["FMUs.SingleWheel", "FMUs.Rover", "FMUs.RoverBody", "FMUs.Wheel", "Examples.RoverReconnected",
          "Components.RigidWheel", "Components.Chassis"]
EXAMPLES = ["Examples.SingleWheelStep", "Examples.RoverOpenLoop", "Examples.RoverReconnectedOpenLoop"]


def full(name: str) -> str:
    return f"{PACKAGE}.{name}"


def documentation(name: str) -> str:
    """The Documentation info of the class ``name`` as text: the Modelica string unescaped, the
    HTML entities resolved (tags kept)."""
    text = source.class_file(full(name)).read_text()
    found = re.search(r'Documentation\(info="(.*?)(?<!\\)"\)', text, re.DOTALL)
    assert found, f"{name}: no Documentation(info=...)"
    return html.unescape(found.group(1).replace('\\"', '"'))


@pytest.mark.parametrize("name", MODELS + EXAMPLES)
def test_model_is_balanced_without_algebraic_loops(name: str):
    info = source.load(full(name)).structure()
    assert info.is_balanced, f"{name}: {info}"
    assert info.is_matched
    assert info.n_equations == info.n_unknowns
    assert info.n_algebraic_loops == 0, f"{name}: {info.n_algebraic_loops} algebraic loops"


@pytest.mark.parametrize("name", MODELS)
def test_every_real_variable_of_a_model_has_a_unit(name: str):
    flat = source.load(full(name)).to_dict("flat")
    types = flat["variable_type_names"]
    missing = [v for v, info in flat["variables"].items() if types.get(v) == "Real" and not info["unit"]]
    assert not missing


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_simulates_over_its_experiment(name: str):
    exp = source.experiment(full(name))
    df = source.simulate(full(name))
    expected_rows = round((exp.stop - exp.start) / exp.interval) + 1
    assert len(df) == expected_rows
    assert df.index[-1] == pytest.approx(exp.stop)
    assert np.isfinite(df.to_numpy()).all()


@pytest.mark.parametrize("name", build.FMU_MODELS)
def test_the_users_guide_lists_inputs_outputs_states_and_parameters(name: str):
    guide = documentation("UsersGuide.Models")
    section = re.search(rf"<h4>{name}</h4>.*?(?=<h4>|\Z)", guide, re.DOTALL)
    assert section, f"UsersGuide.Models has no section <h4>{name}</h4>"
    model = source.load(source.fmu_class(name))
    names = [n for n in list(model.inputs.names) + list(model.outputs.names) + list(model.states.names)
             if "." not in n]
    qualified = list(model.outputs.names) + list(model.states.names)
    components = {n.split(".")[0].split("[")[0] for n in qualified if "." in n}
    flat = model.to_dict("flat")["variables"]
    names += sorted({p.name.split(".")[0].split("[")[0] for p in model.parameters
                     if not flat.get(p.name, {}).get("is_protected", False)} - components)
    for variable in names:
        assert f"<code>{variable}" in section.group(0), f"{name}: {variable} not in its UsersGuide section"


def python_examples() -> list[tuple[str, str]]:
    """The Python examples of the guide (<pre> blocks with an import), of modelica/README.md and of
    the site's page on the library."""
    found = [("UsersGuide.Overview", block) for block in re.findall(r"<pre>\n(.*?)</pre>",
                                                                   documentation("UsersGuide.Overview"), re.DOTALL)
             if block.startswith("from ")]
    for page in (MODELICA_ROOT / "README.md", REPOSITORY / "docs" / "guide" / "modelica.md"):
        found += [(page.name, block) for block in re.findall(r"```python\n(.*?)```", page.read_text(), re.DOTALL)]
    return found


def test_the_python_examples_of_the_guide_run_with_the_installed_import():
    """The guide tells users ``from rover_cosim.fmubuild import source`` (the import of an installed
    rover-cosim; ``fmubuild`` alone is not importable) and its lines run as written."""
    examples = python_examples()
    assert [where for where, _ in examples] == ["UsersGuide.Overview", "README.md", "modelica.md"]
    for where, code in examples:
        assert "from rover_cosim.fmubuild import source" in code and "from fmubuild" not in code, where
        namespace: dict[str, object] = {}
        exec(compile(code, where, "exec"), namespace)  # our own documentation's example, as written
        assert "model" in namespace, where


# --- single-wheel step test against the numpy reference wheel -------------------------------

STEP_LOADS = (275.0, 575.0, 875.0)
STEP_TORQUES = (10.0, 30.0, 60.0, 100.0)


@pytest.fixture(scope="module")
def step_model():
    return source.load(full("Examples.SingleWheelStep"))


def assert_close(name: str, got: np.ndarray, ref: np.ndarray, rtol: float, atol: float) -> None:
    error = np.abs(got - ref)
    bound = rtol * np.abs(ref) + atol
    worst = int(np.argmax(error - bound))
    assert np.all(error <= bound), f"{name}: {got[worst]!r} vs reference {ref[worst]!r} at row {worst}"


@pytest.mark.parametrize("load", STEP_LOADS)
@pytest.mark.parametrize("torque", STEP_TORQUES)
def test_single_wheel_step_agrees_with_the_reference_wheel(step_model, load: float, torque: float):
    """At every output time, (sinkage, Fx, Fz, Tx) of rumoca's simulation equal
    terramechanics.wheel_forces at the same load, spin and speed within 0.5 % (plus an absolute
    floor of 1 mN, 1 mN·m, 0.1 µm for values that pass through zero), and the slip is Eq. (4) of
    the simulated speeds."""
    df = step_model.with_params(W=load, tauStep=torque).simulate(t=(0.0, 2.0), dt=0.002).to_dataframe()
    slip = df["testBed.slip"].to_numpy()
    state = wheel_forces(np.full(slip.shape, load), df["testBed.omega"].to_numpy(), df["testBed.v"].to_numpy())
    assert_close("sinkage", df["testBed.sinkage"].to_numpy(), state.sinkage, 0.005, 1e-7)
    assert_close("Fx", df["testBed.Fx"].to_numpy(), state.Fx, 0.005, 1e-3)
    assert_close("Fz", df["testBed.Fz"].to_numpy(), state.Fz, 0.005, 1e-3)
    assert_close("Tx", df["testBed.Tx"].to_numpy(), state.Tx, 0.005, 1e-3)
    expected_slip = slip_ratio(Wheel().r * df["testBed.omega"].to_numpy(), df["testBed.v"].to_numpy(), 1e-3)
    np.testing.assert_allclose(slip, expected_slip, rtol=0, atol=1e-12)
    np.testing.assert_allclose(df["testBed.Fz"], load, rtol=1e-9)


def test_single_wheel_step_response_settles_to_a_driving_slip(step_model):
    """A torque step from rest: the slip jumps towards 1 while the carriage is still, then
    settles at a steady driving slip; wheel and carriage keep accelerating."""
    df = step_model.with_params(W=575.0, tauStep=60.0).simulate(t=(0.0, 2.0), dt=0.001).to_dataframe()
    slip = df["testBed.slip"].to_numpy()
    assert 0.02 < slip[-1] < 0.5
    assert np.max(np.abs(slip[-500:] - slip[-1])) < 1e-4
    assert np.all(np.diff(df["testBed.v"].to_numpy()[1:]) > 0)


# --- the functions on their own ------------------------------------------------------------

#: Declarations shared by the force probes: outputs, a clock state, the Table 2 records.
PROBE_COMMON = """
  Real Fx(unit="N");
  Real Fz(unit="N");
  Real Tx(unit="N.m");
  Real Fy(unit="N");
  Real FySidewall(unit="N");
  Real clock(start=0, fixed=true);
  RoverTerramechanics.Parameters.SoilParameters soil;
  RoverTerramechanics.Parameters.WheelParameters wheel;
equation
  der(clock) = 1;
"""


def simulate_inline(text: str, model: str, dt: float) -> pd.DataFrame:
    """rumoca's simulation over 0..1 s of a probe model that uses the package."""
    session = rumoca.Session(roots=[str(MODELICA_ROOT)])
    return session.loads(text, model=model).simulate(t=(0.0, 1.0), dt=dt).to_dataframe()


PROBE = """
model ForceProbe
  parameter Real h0(unit="m") = 0.001;
  parameter Real h1(unit="m") = 0.3;
  parameter Real cycles = 7.0;
  Real h(unit="m");
  Real slip(unit="1");
""" + PROBE_COMMON + """  h = h0*(h1/h0)^time;
  slip = -1 + 2*(0.5 - 0.5*cos(2*3.141592653589793*cycles*time));
  (Fx, Fz, Tx, Fy, FySidewall) = RoverTerramechanics.Functions.contactForces(h, slip, soil, wheel, NODES);
end ForceProbe;
"""


def probe_forces(nodes: int) -> pd.DataFrame:
    return simulate_inline(PROBE.replace("NODES", str(nodes)), "ForceProbe", 0.0005)


@pytest.fixture(scope="module")
def probes() -> dict[int, pd.DataFrame]:
    return {nodes: probe_forces(nodes) for nodes in sorted({FMU_NODES, 16, 32})}


def quadrature_errors(df: pd.DataFrame, nodes: int = 12) -> dict[str, np.ndarray]:
    """Relative errors of Fx, Fz, Tx and the largest of Fx's and Fz's over Fz ("scaled") against
    the reference at ``nodes`` (it splits a skidding patch where the shear reverses)."""
    ref = contact_forces(df["h"].to_numpy(), df["slip"].to_numpy(), nodes=nodes)
    return {k: np.abs(df[k].to_numpy() - getattr(ref, k)) / np.abs(getattr(ref, k)) for k in ("Fx", "Fz", "Tx")} | {
        "scaled": np.max([np.abs(df[k].to_numpy() - getattr(ref, k)) for k in ("Fx", "Fz")], axis=0) / ref.Fz}


def test_contact_forces_match_the_reference_quadrature_for_driving_slips(probes):
    """Gauss-Legendre with 16 nodes per piece against the reference:
    sinkage 1 mm to 0.3 m, slip 0..1, pointwise relative error below 1e-6 (composite Simpson
    with 17 nodes per piece, used before, reached 1e-4)."""
    df = probes[16]
    driving = df["slip"].to_numpy() >= 0
    for name, error in quadrature_errors(df).items():
        assert np.max(error[driving]) < 1e-6, name


def test_contact_forces_while_skidding_within_a_thousandth_of_the_load(probes):
    """Skidding, jx changes sign inside the patch and the shear stress has a kink there, which
    the model's quadrature does not split at (the reference does): the error stays below 1e-3
    of Fz and shrinks with more nodes."""
    errors = {nodes: quadrature_errors(df)["scaled"] for nodes, df in probes.items()}
    skidding = probes[16]["slip"].to_numpy() < 0
    assert np.max(errors[16][skidding]) < 1e-3
    assert np.max(errors[32][skidding]) < np.max(errors[16][skidding]) / 2


def test_contact_forces_at_the_models_default_nodes_within_their_stated_error(probes):
    """The FMUs' node count (the Modelica wheel's nNodes) against 96 nodes of the reference within
    the errors UsersGuide.Physics states, with a margin (driving 8e-8 of Fz, skidding 2.2e-5 up to
    h = 0.1 m and 2.2e-3 deeper, where the kink the model does not split at dominates)."""
    df = probes[FMU_NODES]
    scaled = quadrature_errors(df, nodes=96)["scaled"]
    h, slip = df["h"].to_numpy(), df["slip"].to_numpy()
    assert np.max(scaled[slip >= 0]) < 1e-6
    assert np.max(scaled[(slip < 0) & (h <= 0.1)]) < 1e-4
    assert np.max(scaled[slip < 0]) < 5e-3


SINKAGE_PROBE = """
model SinkageProbe
  Real W(unit="N");
  Real slip(unit="1");
  Real h(unit="m");
  Real evaluations(unit="1");
  Real logSinkage(unit="1");
  Real slope(unit="1");
""" + PROBE_COMMON + """  W = 10^(0.5 + 3*time);
  slip = -1 + 2*(0.5 - 0.5*cos(2*3.141592653589793*5*time));
  (h, Fx, Fz, Tx, Fy, FySidewall, evaluations, logSinkage, slope) =
    RoverTerramechanics.Functions.wheelContact(W, slip, soil, wheel);
end SinkageProbe;
"""


def test_wheel_contact_carries_the_load_and_matches_the_reference_sinkage():
    """Loads 3 N to 3 kN, slips -1..1: Fz = W to 1e-9 within the bounded iteration, and the
    sinkage equals the reference wheel's to 1e-4 (the quadratures differ)."""
    df = simulate_inline(SINKAGE_PROBE, "SinkageProbe", 0.001)
    load, slip = df["W"].to_numpy(), df["slip"].to_numpy()
    np.testing.assert_allclose(df["Fz"], load, rtol=1e-9)
    state = wheel_state(load, slip)
    np.testing.assert_allclose(df["h"], state.sinkage, rtol=1e-4)
    # The solve's own count: within the documented 5 force evaluations, never at the bound of 12.
    assert df["evaluations"].min() >= 1 and df["evaluations"].max() <= 5


#: Starts of the warm solve: (offset of log h from the cold solution, slope for the first step or
#: None for the cold solve's): near, a factor 20 above (the fallback), a factor 400 below, exact
#: with a wrong slope.
WARM_STARTS = ((0.003, None), (3.0, None), (-6.0, None), (0.0, 25.0))


def warm_start_probe() -> str:
    lines = ["model WarmStartProbe", '  Real W(unit="N");', '  Real slip(unit="1");', '  Real h(unit="m");',
             '  Real evaluations(unit="1");', '  Real logSinkage(unit="1");', '  Real slope(unit="1");']
    equations = []
    for i, (offset, slope) in enumerate(WARM_STARTS, start=1):
        names = [f"{name}{i}" for name in ("h", "Fx", "Fz", "Tx", "Fy", "FySidewall", "evaluations", "logSinkage",
                                           "slope")]
        lines += [f"  Real {name};" for name in names]
        # the nodes and the 12 iterations the cold solve below takes by default
        equations.append(f"  ({', '.join(names)}) = RoverTerramechanics.Functions.wheelContact(W, slip, soil, wheel, "
                         f"{FMU_NODES}, 12, 1e-10, 1e-3, 0, logSinkage + ({offset}), {slope if slope else 'slope'});")
    return "\n".join(lines) + PROBE_COMMON + """  W = 10^(0.5 + 3*time);
  slip = -1 + 2*(0.5 - 0.5*cos(2*3.141592653589793*5*time));
  (h, Fx, Fz, Tx, Fy, FySidewall, evaluations, logSinkage, slope) =
    RoverTerramechanics.Functions.wheelContact(W, slip, soil, wheel);
""" + "\n".join(equations) + "\nend WarmStartProbe;\n"


def test_wheel_contact_warm_start_gives_the_cold_result():
    """The sinkage solve started anywhere (near the solution, a factor 20 above it: the fallback to
    the cold start, a factor 400 below, exactly at it with a wrong slope) finds the cold solve's
    sinkage to its tolerance; near the solution it needs fewer force evaluations."""
    df = simulate_inline(warm_start_probe(), "WarmStartProbe", 0.001)
    cold, load = df["h"].to_numpy(), df["W"].to_numpy()
    for i in range(1, len(WARM_STARTS) + 1):
        np.testing.assert_allclose(df[f"Fz{i}"], load, rtol=1e-9)
        np.testing.assert_allclose(df[f"h{i}"], cold, rtol=1e-9)
        assert df[f"evaluations{i}"].max() <= 8, i
    assert df["evaluations4"].max() == 1  # a converged start is accepted at once
    assert df["evaluations1"].mean() < df["evaluations"].mean() - 1


SLIP_PROBE = """
model SlipProbe
  Real rOmega(unit="m/s");
  Real v(unit="m/s");
  Real slip(unit="1");
  Real clock(start=0, fixed=true);
equation
  der(clock) = 1;
  rOmega = 2*sin(2*3.141592653589793*3*time) * (if time < 0.5 then 1 else 1e-3);
  v = cos(2*3.141592653589793*5*time) * (if time < 0.25 or time > 0.75 then 1 else 1e-3);
  slip = RoverTerramechanics.Functions.slipRatio(rOmega, v, 1e-3);
end SlipProbe;
"""


def test_slip_ratio_matches_the_reference_including_rest_and_sign_changes():
    df = simulate_inline(SLIP_PROBE, "SlipProbe", 0.0005)
    expected = slip_ratio(df["rOmega"].to_numpy(), df["v"].to_numpy(), 1e-3)
    np.testing.assert_allclose(df["slip"], expected, rtol=0, atol=1e-12)
    assert np.all(np.abs(df["slip"]) <= 1)


# --- the rover ----------------------------------------------------------------------------

@pytest.fixture(scope="module")
def rover_runs() -> dict[str, pd.DataFrame]:
    return {name: source.simulate(full(f"Examples.{name}"))
            for name in ("RoverOpenLoop", "RoverReconnectedOpenLoop")}


ROVER_OUTPUTS = ["x", "v", "pitch"] + [f"{k}[{i}]" for k in ("Fz", "Fx", "Tx", "slip", "sinkage", "omega")
                                       for i in range(1, 7)]


def test_reconnected_rover_gives_the_monolithic_trajectories(rover_runs):
    mono, split = rover_runs["RoverOpenLoop"], rover_runs["RoverReconnectedOpenLoop"]
    assert np.array_equal(mono.index, split.index)
    for name in ROVER_OUTPUTS:
        a, b = mono[f"rover.{name}"].to_numpy(), split[f"rover.{name}"].to_numpy()
        scale = max(np.max(np.abs(a)), 1e-9)
        assert np.max(np.abs(a - b)) <= 1e-6 * scale, name


def test_rover_starts_in_static_equilibrium_on_equal_loads(rover_runs):
    df = rover_runs["RoverOpenLoop"]
    weight = 1570 * 1.62
    first = df.iloc[0]
    for i in range(1, 7):
        assert first[f"rover.Fz[{i}]"] == pytest.approx(weight / 6, rel=1e-9)


def test_acceleration_unloads_the_front_limbs_and_loads_the_rear(rover_runs):
    """Paper Fig. 10c: while accelerating (here 0.3-2.5 s) Fz of limb 1 falls and Fz of limb 3
    rises; the mirrored limbs 4-6 carry the same loads; the total still carries the weight."""
    df = rover_runs["RoverOpenLoop"]
    weight = 1570 * 1.62
    accelerating = df[(df.index >= 0.3) & (df.index <= 2.5)]
    assert np.all(np.diff(df["rover.v"][df.index <= 2.5].to_numpy()) > 0)
    assert np.all(accelerating["rover.Fz[1]"] < 0.9 * weight / 6)
    assert np.all(accelerating["rover.Fz[3]"] > 1.1 * weight / 6)
    assert np.all(accelerating["rover.pitch"] > 0)
    for i in range(1, 4):
        np.testing.assert_allclose(df[f"rover.Fz[{i}]"], df[f"rover.Fz[{i + 3}]"], rtol=1e-12)
    total = sum(accelerating[f"rover.Fz[{i}]"] for i in range(1, 7))
    np.testing.assert_allclose(total, weight, rtol=0.01)
    assert df["rover.v"].iloc[-1] == pytest.approx(1.0, abs=0.1)


def test_the_users_guide_states_the_wheels_structural_defaults_the_models_have():
    """UsersGuide.Models states nNodes and nIterations in prose, "<code>nNodes</code> (10)" or
    "<code>nNodes</code> = 10": each such number is the Modelica wheel's default."""
    wheel = (MODELICA_ROOT / PACKAGE / "Components" / "RigidWheel.mo").read_text()
    guide = (MODELICA_ROOT / PACKAGE / "UsersGuide" / "Models.mo").read_text()
    for name in ("nNodes", "nIterations"):
        default = re.search(rf"parameter Integer {name} = (\d+)", wheel)
        assert default is not None, name
        stated = re.findall(rf"<code>{name}</code> (?:\((\d+)\)|= (\d+))", guide)
        assert stated, f"UsersGuide.Models does not state {name}"
        assert {a or b for a, b in stated} == {default.group(1)}, (name, stated)
