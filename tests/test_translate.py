"""The built-in exporter's front half: rumoca flat model → CasADi ODE (fmubuild.ode), checked
against rumoca's own simulation of the same Modelica, its rejections of what it cannot translate,
and the public variables of every FMU model against the list they are held to."""

from __future__ import annotations

import json
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
import rumoca

from rover_cosim.fmubuild import build, codegen, source
from rover_cosim.fmubuild.expressions import UnsupportedConstruct
from rover_cosim.fmubuild.ode import translate


def integrate(ode, params: dict[str, float], stop: float, interval: float):
    values = dict(ode.parameter_values) | params
    p = ca.DM([values[n] for n in ode.parameters])
    grid = np.arange(0.0, stop + interval / 2, interval)
    xdot, y = ode.at_memory_defaults()
    dae = {"x": ode.x, "t": ode.t, "p": ode.p, "ode": xdot}
    integrator = ca.integrator("I", "cvodes", dae, 0.0, grid[1:], {"reltol": 1e-10, "abstol": 1e-10})
    x0 = ca.Function("x0", [ode.p], [ode.x0])(p)
    states = np.hstack([np.array(x0), np.array(integrator(x0=x0, p=p)["xf"])])
    outputs = ca.Function("g", [ode.t, ode.x, ode.u, ode.p], [y])
    observed = np.hstack([np.array(outputs(t, states[:, k], ca.DM.zeros(0), p)) for k, t in enumerate(grid)])
    return grid, dict(zip(ode.states, states)) | dict(zip(ode.observed, observed))


def test_single_wheel_step_ode_matches_rumocas_simulation():
    name = f"{source.PACKAGE}.Examples.SingleWheelStep"
    params = {"W": 575.0, "tauStep": 60.0}
    grid, ours = integrate(translate(source.load(name), name), params, 2.0, 0.01)
    theirs = source.simulate(name, params=params, stop=2.0, interval=0.01)
    np.testing.assert_allclose(grid, theirs.index)
    for column, atol in (("testBed.slip", 1e-4), ("testBed.Fx", 0.05), ("testBed.v", 1e-6),
                         ("testBed.sinkage", 1e-6), ("testBed.omega", 1e-5)):
        np.testing.assert_allclose(ours[column], theirs[column], rtol=0, atol=atol, err_msg=column)


def test_open_loop_rover_ode_matches_rumocas_simulation():
    name = f"{source.PACKAGE}.Examples.RoverOpenLoop"
    _, ours = integrate(translate(source.load(name), name), {}, 1.0, 0.01)
    theirs = source.simulate(name, stop=1.0, interval=0.01)
    for column, atol in (("rover.v", 1e-5), ("rover.Fz[1]", 0.05), ("rover.Fz[3]", 0.05),
                         ("rover.pitch", 1e-6), ("rover.slip[3]", 1e-4)):
        np.testing.assert_allclose(ours[column], theirs[column], rtol=0, atol=atol, err_msg=column)


@pytest.mark.parametrize("name, inputs", [
    ("SingleWheel", ["tau", "rutDepth", "trackAngle"]),
    ("Wheel", ["tau", "W", "v_hub", "v_lat", "soilShare", "rutDepth"]),
    ("RoverBody", [f"Fx[{i}]" for i in range(1, 7)] + [f"tau[{i}]" for i in range(1, 7)]),
    ("Rover", [f"tau[{i}]" for i in range(1, 7)] + [f"rutDepth[{i}]" for i in range(1, 7)]),
])
def test_fmu_models_translate_with_their_interfaces(name: str, inputs: list[str]):
    ode = translate(source.load(source.fmu_class(name)), name)
    assert ode.inputs == inputs
    outputs = [v.name for v in ode.variables.values() if v.role == "output"]
    assert outputs and all(o in ode.observed or o in ode.states for o in outputs)
    _, _, initial = ode.functions()
    p = ca.DM([ode.parameter_values[n] for n in ode.parameters])
    xdot, _ = ode.at_memory_defaults()
    jac = ca.Function("j", [ode.t, ode.x, ode.u, ode.p], [ca.jacobian(xdot, ode.x)])
    u = ca.DM([424.0 if n == "W" else 10.0 for n in ode.inputs])
    assert np.isfinite(np.array(jac(0.0, initial(p), u, p))).all()


#: The public variables (parameters, inputs, outputs: name, causality, variability) of every FMU,
#: as the FMUs had them when their classes moved into RoverTerramechanics.FMUs (captured from the
#: layout of the models before the move). A difference is a change of the FMUs' interface: make it
#: deliberately, here and in the CHANGELOG.
FMU_VARIABLES = json.loads((Path(__file__).parent / "fmu_variables.json").read_text())


def public_variables(name: str) -> list[list[str]]:
    """The FMU ``name``'s parameters, inputs and outputs as [name, causality, variability], in the
    order of its value references."""
    layout = codegen.layout(translate(source.load(source.fmu_class(name)), name))
    return [[v.name, v.causality, v.variability] for v in layout.variables
            if v.causality in ("parameter", "input", "output")]


@pytest.mark.parametrize("name", build.FMU_MODELS)
def test_the_public_variables_of_each_fmu_are_those_it_always_had(name: str):
    """What a user of the FMU sees by name: the exporter's variable layout (the model description's
    ModelVariables) of the class the FMU is built from, against the captured list."""
    public = public_variables(name)
    assert name in FMU_VARIABLES, (f"{name}: a new FMU, its variables not pinned yet: pin them with "
                                   f"`python tests/test_translate.py {name}` (writes tests/fmu_variables.json)")
    expected = FMU_VARIABLES[name]
    missing = [v for v in expected if v not in public]
    added = [v for v in public if v not in expected]
    assert not missing and not added, f"{name}: missing {missing}, added {added}"
    assert public == expected, f"{name}: the same variables in another order (value references change)"


BAD_MODELS = {
    "when": ("""model Bad
  Real x(start=0, fixed=true);
  Real y(start=0);
equation
  der(x) = 1;
  when x > 0.5 then
    y = pre(y) + 1;
  end when;
end Bad;""", "when"),
    "nonlinear": ("""model Bad
  Real x(start=0, fixed=true);
  Real y;
equation
  der(x) = y;
  y^3 + y = time;
end Bad;""", "nonlinear"),
    "event": ("""model Bad
  Real x(start=0, fixed=true);
equation
  der(x) = if x > 1 then 0 else 1;
end Bad;""", "noEvent"),
    "initial equation": ("""model Bad
  Real x(start=0);
initial equation
  x = 2;
equation
  der(x) = -x;
end Bad;""", "initial equation"),
}


@pytest.mark.parametrize("case", sorted(BAD_MODELS))
def test_unsupported_constructs_get_a_clear_error_naming_the_source_line(case: str):
    text, expected = BAD_MODELS[case]
    try:
        model = rumoca.Session().loads(text, model="Bad", filename="Bad.mo")
    except rumoca.RumocaError as error:  # rumoca itself refuses it: also a clear error, earlier
        pytest.skip(f"rumoca rejects the {case} model before translation: {error}")
    with pytest.raises(UnsupportedConstruct) as info:
        translate(model, "Bad")
    message = str(info.value)
    assert expected in message
    assert "omc" in message
    assert "Bad.mo:" in message


def test_an_unsupported_construct_survives_the_trip_from_a_build_worker():
    """A parallel build's worker hands its exception to the parent pickled: an UnsupportedConstruct
    must come back whole (it came back as a broken pool, "a process in the process pool was
    terminated abruptly", which named nothing)."""
    import pickle

    from rover_cosim.fmubuild.expressions import UnsupportedConstruct

    error = UnsupportedConstruct("an input the solver lacks comes first", "contactResidual")
    copy = pickle.loads(pickle.dumps(error))
    assert type(copy) is UnsupportedConstruct and str(copy) == str(error)
    assert (copy.what, copy.where) == (error.what, error.where)


if __name__ == "__main__":  # `python tests/test_translate.py NAME...`: pin the variables of new FMUs
    import sys

    for new in sys.argv[1:]:
        if new in FMU_VARIABLES:
            sys.exit(f"{new}: already pinned; a change of its variables is a change of its interface: edit the "
                     "pin deliberately, and say so in the CHANGELOG")
        FMU_VARIABLES[new] = public_variables(new)
    pins = [f"  {json.dumps(name)}: [\n" + ",\n".join(f"    {json.dumps(v)}" for v in variables) + "\n  ]"
            for name, variables in FMU_VARIABLES.items()]
    (Path(__file__).parent / "fmu_variables.json").write_text("{\n" + ",\n".join(pins) + "\n}\n")



GUARDED_LOOPS = """model Loops
  function half "One Newton step of sqrt(a) from x (a function call inside the loop: a Switch)"
    input Real x;
    input Real a;
    output Real y;
  algorithm
    y := 0.5*(x + a/x);
  end half;
  function root "sqrt(a) by Newton, the remaining iterations skipped once converged"
    input Real a;
    input Integer n = 12;
    output Real x;
    output Real steps;
  protected
    Boolean done;
  algorithm
    x := a;
    steps := 0;
    done := false;
    for k in 1:n loop
      if not done then
        x := half(x, a);
        steps := steps + 1;
        done := noEvent(abs(x*x - a) <= 1e-12*a);
      end if;
    end for;
  end root;
  function counted "Steps from the third on: the guard refers to the loop index (not nested)"
    input Real a;
    input Integer n = 6;
    output Real x;
  algorithm
    x := a;
    for k in 1:n loop
      if noEvent(k > 2 and x > 1.5) then
        x := half(x, 2.0);
      end if;
    end for;
  end counted;
  function inline "root's loop without a function call: both branches computed, not nested"
    input Real a;
    output Real x;
  protected
    Boolean done;
  algorithm
    x := a;
    done := false;
    for k in 1:12 loop
      if not done then
        x := 0.5*(x + a/x);
        done := noEvent(abs(x*x - a) <= 1e-12*a);
      end if;
    end for;
  end inline;
  input Real a;
  output Real r;
  output Real s;
  output Real c;
  output Real q;
equation
  (r, s) = root(a);
  c = counted(a);
  q = inline(a);
end Loops;"""


def test_loops_with_a_guard_skip_their_remaining_iterations_and_compute_the_same():
    """A loop body ``if guard then ... end if`` that calls a function, with a guard that does not
    refer to the index, is translated as nested branches (a false guard skips every later iteration
    at once); one whose guard refers to the index, or without a call, is not. All compute what the
    Modelica says, at every input."""
    model = rumoca.Session().loads(GUARDED_LOOPS, model="Loops", filename="Loops.mo")
    ode = translate(model, "Loops")
    _, y = ode.at_memory_defaults()
    outputs = ca.Function("g", [ode.u, ode.p], [y])
    names = list(ode.observed)

    def expected(a: float) -> tuple[float, float, float]:
        x, steps = a, 0
        for _ in range(12):
            x = 0.5 * (x + a / x)
            steps += 1
            if abs(x * x - a) <= 1e-12 * a:
                break
        c = a
        for k in range(1, 7):
            if k > 2 and c > 1.5:
                c = 0.5 * (c + 2.0 / c)
        return x, steps, c

    for a in (0.3, 2.0, 9.0, 1e4, 1e9):
        values = np.array(outputs(ca.DM([a]), ca.DM([ode.parameter_values[n] for n in ode.parameters]))).ravel()
        got = dict(zip(names, values))
        x, steps, c = expected(a)
        assert got["r"] == x and got["s"] == steps and got["c"] == c, (a, got, (x, steps, c))
        assert got["q"] == x, (a, got["q"], x)
    assert expected(1e9)[1] == 12 and expected(2.0)[1] < 12  # both ends of the loop are exercised
