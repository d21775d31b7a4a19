"""An :class:`~fmubuild.ode.OdeModel` → the C sources of one FMU and the layout of its variables.

Generated per model (the runtime in ``fmubuild/runtime`` is the same for all):

- ``model_casadi.c``: CasADi's C code (its SX functions rewritten by :mod:`fmubuild.guards` so
  that a branch of a run-time ``if`` is computed only when taken) of ``model_evaluate``
  (derivatives, outputs, the model's ``assert`` conditions and the values they read, in one
  evaluation), ``model_initial``,
  ``model_ode_jacobian`` (dense df/dx and df/dt, for the Co-Simulation integrator) and
  ``model_directional`` (forward directional derivatives of derivatives and observed variables,
  for ``fmi2GetDirectionalDerivative``) and ``model_input_gain`` (d xdot / d u of the inputs the
  derivatives are affine in, :func:`affine_inputs`);
- ``model_data.c``: the ``ModelInfo`` of ``runtime/model.h`` (sizes, defaults, names, GUID).

Real value references follow ``runtime/model.h``: parameters, states, derivatives, inputs, observed
variables (outputs and locals), memories (:mod:`fmubuild.memory`),
then the two solver parameters and the runtime's statistics.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

import casadi as ca

from .contact import use_contact_kernel
from .elementary import use_own_elementary
from .guards import guard_generated_code
from .ode import OdeModel

#: Solver parameters appended after the model's variables (Co-Simulation only).
SOLVER_PARAMETERS = (
    ("solver.tolerance", 1e-6, "1",
     "Relative (and absolute) tolerance of the Co-Simulation integrator (Rosenbrock 2(3), error-controlled)"),
    ("solver.maxStep", 0.0, "s",
     "Largest internal step of the Co-Simulation integrator; 0: only the communication step limits it"),
)

#: Counters of the runtime, since the instance was made (read-only locals after the solver
#: parameters): what a benchmark or a curious user reads to see where the time goes.
STATISTICS = (
    ("statistics.evaluations", "Evaluations of the model (derivatives and outputs together)"),
    ("statistics.reusedEvaluations", "Requests answered by the last evaluation (same time, states and inputs)"),
    ("statistics.jacobians", "Evaluations of the Jacobian by the Co-Simulation integrator"),
    ("statistics.steps", "Accepted steps of the Co-Simulation integrator"),
    ("statistics.rejectedSteps", "Rejected steps of the Co-Simulation integrator"),
    ("statistics.derivativeUpdates",
     "Steps of the Co-Simulation integrator that began from the last derivatives updated for inputs that enter "
     "them linearly, without an evaluation"),
)


#: First lines of model_casadi.c: with FMI2_FUNCTION_PREFIX defined, fmu_prefix.h (written by the
#: build) prefixes CasADi's external names too, before CasADi's own prefix block reads it.
PREFIX_INCLUDE = '#ifdef FMI2_FUNCTION_PREFIX\n#include "fmu_prefix.h"\n#endif\n'


@dataclass(frozen=True)
class FmuVariable:
    """One ScalarVariable of the model description (value reference = position in the layout)."""

    name: str
    value_reference: int
    kind: str  # "parameter", "state", "derivative", "input", "observed", "solver", "statistic"
    causality: str
    variability: str
    initial: str | None
    start: float | None
    unit: str | None
    description: str | None
    derivative_of: int | None = None  # value reference of the state, for derivatives
    minimum: float | None = None      # the Modelica declaration's min, in ``unit``
    maximum: float | None = None      # the Modelica declaration's max, in ``unit``
    display_unit: str | None = None   # the Modelica declaration's displayUnit


@dataclass(frozen=True)
class ModelLayout:
    """What the model description and the C data need, in value-reference order."""

    name: str
    variables: list[FmuVariable]
    n_states: int
    n_inputs: int
    n_parameters: int
    n_observed: int
    dependencies: dict[int, list[int]]  # value reference of a derivative/observed -> state/input refs
    state_starts: list[float]  # start of every state at the default parameters (calculated ones too)


def _functions(model: OdeModel, u_affine: list[int]) -> tuple[list[ca.Function], list[ca.Function]]:
    """The generated functions: those of every step (evaluate, initial, the input gain) and the
    derivatives' (the integrator's Jacobian, every hundred steps or so, and the directional
    derivatives of fmi2GetDirectionalDerivative)."""
    t, x, u, p, m = model.t, model.x, model.u, model.p, model.m
    dx = ca.MX.sym("dx", x.numel())
    du = ca.MX.sym("du", u.numel())
    knowns = ca.vertcat(x, u)
    seeds = ca.vertcat(dx, du)
    # Derivatives from the graphs with the implicit solves' derivatives (fmubuild.implicit): the
    # same values as model_evaluate's, the derivative of the solution rather than of its iterations.
    xdot_d = model.xdot if model.xdot_derivative is None else model.xdot_derivative
    y_d = model.y if model.y_derivative is None else model.y_derivative
    sensitivity = ca.jtimes(ca.vertcat(xdot_d, y_d), knowns, seeds) if knowns.numel() else ca.MX(
        model.xdot.numel() + model.y.numel(), 1)
    nx = x.numel()
    evaluate = ca.Function("model_evaluate", [t, x, u, p, m],
                           [model.xdot, model.y, _column([a.condition for a in model.asserts]),
                            _column([value for a in model.asserts for value in a.values])],
                           ["t", "x", "u", "p", "m"], ["xdot", "y", "holds", "values"])
    derivatives = [
        ca.Function("model_ode_jacobian", [t, x, u, p, m],
                    [ca.densify(ca.jacobian(xdot_d, x)), ca.densify(ca.jacobian(xdot_d, t))],
                    ["t", "x", "u", "p", "m"], ["dfdx", "dfdt"]),
        ca.Function("model_directional", [t, x, u, p, m, dx, du],
                    [ca.densify(sensitivity[:nx]), ca.densify(sensitivity[nx:])],
                    ["t", "x", "u", "p", "m", "dx", "du"], ["dxdot", "dy"]),
    ]
    # Derivatives and outputs in one function, so that they share one evaluation of the model (e.g.
    # one sinkage solve per wheel); the runtime keeps the last one with the point it was made at.
    # The asserts come with it: an importer reading outputs after each step gets them checked at no
    # extra cost. The functions of every step first, the derivatives' after them (COLD_CODE).
    return [evaluate, ca.Function("model_initial", [p], [model.x0], ["p"], ["x0"]),
            _input_gain(model, xdot_d, u_affine)], derivatives


def _input_gain(model: OdeModel, xdot: ca.MX, u_affine: list[int]) -> ca.Function:
    """``model_input_gain(t, x, u, p, m) -> gain``: d xdot / d u [nx x nu, column-major, dense] in
    the columns of the inputs the derivatives are affine in (0 in the others), for the runtime's
    update of the derivatives when only those change (instance.c: input_gain). Those columns read
    only the parameters and the other inputs: expanded to scalar operations they are a few hundred
    (LegWheelRover: 454 against the 22,228 of the graph's Jacobian), so the runtime takes the gain
    again cheaply whenever a set-point it reads has moved."""
    t, x, u, p, m = model.t, model.x, model.u, model.p, model.m
    nx, nu = x.numel(), u.numel()
    if nx and nu and any(u_affine):
        jacobian = ca.jacobian(xdot, u)
        gain = ca.horzcat(*[jacobian[:, j] if u_affine[j] else ca.MX(nx, 1) for j in range(nu)])
    else:
        gain = ca.MX(nx, nu)
    function = ca.Function("model_input_gain", [t, x, u, p, m], [ca.densify(gain)],
                           ["t", "x", "u", "p", "m"], ["gain"])
    try:
        return function.expand()
    except RuntimeError:  # a node that has no scalar form: the graph's Jacobian, as correct, slower
        return function


def affine_inputs(model: OdeModel) -> list[int]:
    """Per input, 1 where the derivatives are affine in it: d xdot / d u_j depends on none of the
    time, the states, the memories and the inputs so marked (it may depend on the parameters and
    the other inputs: a motor torque whose reaction turns with a steering set-point), else 0. For
    those the Co-Simulation runtime updates the derivatives it has for a change of the input,
    xdot += (d xdot / d u_j) du_j, instead of evaluating the model again (instance.c:
    rc_set_real); the gain is taken where the other inputs are."""
    u = model.u
    nu = u.numel()
    xdot = model.xdot if model.xdot_derivative is None else model.xdot_derivative
    gain = ca.jacobian(xdot, u) if nu and model.x.numel() else ca.MX(0, 0)
    if not gain.nnz():
        return [0] * nu
    entries = gain.nz[:]  # the structural nonzeros, column by column; which variables each reads:
    _, column = gain.sparsity().get_triplet()
    varying = {column[r] for v in (model.t, model.x, model.m) if v.numel()
               for r in ca.jacobian_sparsity(entries, v).get_triplet()[0]}
    reads: dict[int, set[int]] = {}
    for r, k in zip(*ca.jacobian_sparsity(entries, u).get_triplet()):
        reads.setdefault(column[r], set()).add(k)
    chosen = {j for j in range(nu) if j not in varying}
    while True:  # nor on an input so marked (u_j u_k is affine in neither)
        kept = {j for j in chosen if not reads.get(j, set()) & chosen}
        if kept == chosen:
            return [1 if j in chosen else 0 for j in range(nu)]
        chosen = kept


def _column(entries: list[ca.MX]) -> ca.MX:
    return ca.densify(ca.vertcat(*entries)) if entries else ca.MX(0, 1)


def _state_starts(model: OdeModel) -> tuple[list[float], list[bool]]:
    """Start value of each state at the default parameters, and whether it is calculated from them."""
    if not model.states:
        return [], []
    x0 = ca.Function("x0", [model.p], [model.x0])
    default_p = [model.parameter_values[n] for n in model.parameters]
    starts = [float(value) for value in ca.DM(x0(default_p)).full().ravel()]
    calculated = [bool(ca.depends_on(model.x0[i], model.p)) if model.p.numel() else False
                  for i in range(len(model.states))]
    return starts, calculated


def _variables(model: OdeModel, starts: list[float], calculated: list[bool]) -> list[FmuVariable]:
    """Every FMU variable with its value reference, in the layout of model.h; ``starts`` and
    ``calculated`` as from :func:`_state_starts`."""
    variables: list[FmuVariable] = []

    def add(**kwargs: object) -> FmuVariable:
        variable = FmuVariable(value_reference=len(variables), **kwargs)  # type: ignore[arg-type]
        variables.append(variable)
        return variable

    info = model.variables
    for name in model.parameters:
        v = info[name]
        add(name=name, kind="parameter", causality="parameter", variability="fixed", initial="exact",
            start=model.parameter_values[name], unit=v.unit, description=v.description, minimum=v.minimum,
            maximum=v.maximum, display_unit=v.display_unit)
    state_refs = [add(name=name, kind="state", causality="output" if info[name].is_output else "local",
                      variability="continuous", initial="calculated" if calculated[i] else "exact",
                      start=None if calculated[i] else starts[i], unit=info[name].unit,
                      description=info[name].description)
                  for i, name in enumerate(model.states)]
    for state, name in zip(state_refs, model.states):
        add(name=f"der({name})", kind="derivative", causality="local", variability="continuous", initial="calculated",
            start=None, unit=_derivative_unit(info[name].unit), description=f"time derivative of {name}",
            derivative_of=state.value_reference)
    for name in model.inputs:
        v = info[name]
        add(name=name, kind="input", causality="input", variability="continuous", initial=None,
            start=v.start if v.start is not None else 0.0, unit=v.unit, description=v.description, minimum=v.minimum,
            maximum=v.maximum, display_unit=v.display_unit)
    for name in model.observed:
        v = info[name]
        add(name=name, kind="observed", causality="output" if v.is_output else "local", variability="continuous",
            initial="calculated", start=None, unit=v.unit, description=v.description, display_unit=v.display_unit)
    for name in model.memories:
        v = info[name]
        add(name=name, kind="memory", causality="local", variability="continuous", initial="calculated", start=None,
            unit=v.unit, description=v.description)
    for name, value, unit, description in SOLVER_PARAMETERS:
        add(name=name, kind="solver", causality="parameter", variability="tunable", initial="exact", start=value,
            unit=unit, description=description)
    for name, description in STATISTICS:
        add(name=name, kind="statistic", causality="local", variability="continuous", initial="calculated",
            start=None, unit="1", description=description)
    return variables


def layout(model: OdeModel) -> ModelLayout:
    """Value references, causality/variability/initial, start values and dependencies."""
    x_start, calculated = _state_starts(model)
    variables = _variables(model, x_start, calculated)
    # Structural dependencies of derivatives and observed variables on states and inputs.
    knowns = ca.vertcat(model.x, model.u)
    known_refs = [v.value_reference for v in variables if v.kind in ("state", "input")]
    unknown_refs = [v.value_reference for v in variables if v.kind in ("derivative", "observed")]
    dependencies: dict[int, list[int]] = {ref: [] for ref in unknown_refs}
    if knowns.numel() and unknown_refs:
        pattern = ca.jacobian_sparsity(ca.vertcat(model.xdot, model.y), knowns)
        rows, cols = pattern.get_triplet()
        for r, c in zip(rows, cols):
            dependencies[unknown_refs[r]].append(known_refs[c])
    for refs in dependencies.values():
        refs.sort()
    return ModelLayout(model.name, variables, len(model.states), len(model.inputs), len(model.parameters),
                       len(model.observed), dependencies, x_start)


def _derivative_unit(unit: str | None) -> str | None:
    if unit is None:
        return None
    if unit in ("", "1"):
        return "1/s"
    if "/" in unit:
        numerator, denominator = unit.split("/", 1)
        if denominator == "s":
            return f"{numerator}/s2"
        if denominator == "s2":
            return f"{numerator}/s3"
        return f"{numerator}/({denominator}.s)"
    return f"{unit}/s"


def _c_doubles(values: list[float]) -> str:
    return "{" + ", ".join(repr(float(v)) for v in values) + "}" if values else "{0.0}"


def _c_string(text: str) -> str:
    return json.dumps(text)  # a valid C string literal for printable text


#: Around the derivatives' code (the Jacobian and the directional derivatives: four fifths of a
#: rover's generated C, run every hundred steps or so): GCC compiles it at -O1, which halves an
#: FMU's compile time (Rover's model_casadi.c 10.9 -> 5.1 s) and gives the same bits (no
#: floating-point change between the levels); other compilers ignore it.
COLD_CODE = ("#if defined(__GNUC__) && !defined(__clang__)\n#pragma GCC push_options\n"
             "#pragma GCC optimize (\"O1\")\n#endif\n",
             "#if defined(__GNUC__) && !defined(__clang__)\n#pragma GCC pop_options\n#endif\n")


def _cold_code_at_o1(code: str, last_hot: str) -> str:
    """``code`` with COLD_CODE around what follows the last function of the hot group (CasADi emits
    each function after the helpers it is first to use, its interface functions last)."""
    start = code.index(f"int {last_hot}_work_bytes(")
    end = code.index("\n}\n", start) + 3
    return code[:end] + COLD_CODE[0] + code[end:] + COLD_CODE[1]


def write_sources(model: OdeModel, model_layout: ModelLayout, directory: Path, *,
                  own_elementary: bool = False) -> str:
    """Write ``model_casadi.c`` and ``model_data.c`` to ``directory``; returns the GUID, a digest of
    the generated code and the layout (same model, same GUID). ``own_elementary``: the generated
    code calls ``runtime/elementary.h``'s functions (fmubuild.elementary)."""
    directory.mkdir(parents=True, exist_ok=True)
    generator = ca.CodeGenerator("model_casadi.c", {"with_export": False, "with_header": False,
                                                     "casadi_int": "long long int", "casadi_real": "double"})
    u_affine = affine_inputs(model)
    hot, cold = _functions(model, u_affine)
    for function in (*hot, *cold):
        generator.add(function)
    # Each branch of a run-time if computed only when taken (fmubuild.guards).
    code, _ = guard_generated_code(generator.dump())
    code = _cold_code_at_o1(code, hot[-1].name())
    # The contact's quadrature as vector code where the wheel allows (fmubuild.contact).
    code = use_contact_kernel(code)
    if own_elementary:  # the same elementary functions on every host (fmubuild.elementary)
        code = use_own_elementary(code)
    digest = hashlib.sha256(code.encode())
    variables = [(v.name, v.kind, v.causality, v.start, v.unit) for v in model_layout.variables]
    assert_texts = [(a.message, a.level, a.names) for a in model.asserts]
    digest.update(json.dumps([model.name, variables, sorted(model_layout.dependencies.items()),
                              assert_texts]).encode())
    h = digest.hexdigest()
    guid = "{" + f"{h[:8]}-{h[8:12]}-{h[12:16]}-{h[16:20]}-{h[20:32]}" + "}"
    (directory / "model_casadi.c").write_text(
        "/* Generated by rover-cosim fmubuild with CasADi " + ca.CasadiMeta.version() + " from the Modelica model "
        + model.name + ". Do not edit. */\n" + PREFIX_INCLUDE + code)

    by_kind: dict[str, list[FmuVariable]] = {}
    for v in model_layout.variables:
        by_kind.setdefault(v.kind, []).append(v)
    p_default = [v.start or 0.0 for v in by_kind.get("parameter", [])]
    u_default = [v.start or 0.0 for v in by_kind.get("input", [])]
    states = by_kind.get("state", [])
    x_start = model_layout.state_starts
    calculated = [1 if v.initial == "calculated" else 0 for v in states]
    memory_source = [model.observed.index(source) for source in model.memory_sources]
    y_is_output = [1 if v.causality == "output" else 0 for v in by_kind.get("observed", [])]
    names = ",\n    ".join(_c_string(v.name) for v in model_layout.variables)
    asserts = model.asserts
    value_start = [0]
    for a in asserts:
        value_start.append(value_start[-1] + len(a.values))
    messages = ", ".join(_c_string(a.message) for a in asserts) or '""'
    levels = ", ".join("1" if a.level == "error" else "0" for a in asserts) or "0"
    value_names = ", ".join(_c_string(n) for a in asserts for n in a.names) or '""'
    assert_data = f"""static const char *const ASSERT_MESSAGES[] = {{{messages}}};
static const int ASSERT_IS_ERROR[] = {{{levels}}};
static const int ASSERT_VALUE_START[] = {{{", ".join(map(str, value_start))}}};
static const char *const ASSERT_VALUE_NAMES[] = {{{value_names}}};
"""
    data = f"""/* Generated by rover-cosim fmubuild: the layout of {model.name}. Do not edit. */
#include "model.h"

static const double P_DEFAULT[] = {_c_doubles(p_default)};
static const double U_DEFAULT[] = {_c_doubles(u_default)};
static const double X_START[] = {_c_doubles(x_start)};
static const int X_START_CALCULATED[] = {{{", ".join(map(str, calculated)) or "0"}}};
static const double M_DEFAULT[] = {_c_doubles(model.memory_defaults)};
static const int M_SOURCE[] = {{{", ".join(map(str, memory_source)) or "0"}}};
static const int Y_IS_OUTPUT[] = {{{", ".join(map(str, y_is_output)) or "0"}}};
static const int U_AFFINE[] = {{{", ".join(map(str, u_affine)) or "0"}}};
static const char *const REAL_NAMES[] = {{
    {names}
}};
{assert_data}
const ModelInfo model_info = {{
    {_c_string(model.name)}, {_c_string(guid)},
    {model_layout.n_states}, {model_layout.n_inputs}, {model_layout.n_parameters}, {model_layout.n_observed},
    P_DEFAULT, U_DEFAULT, X_START, X_START_CALCULATED, REAL_NAMES,
    {len(asserts)}, ASSERT_MESSAGES, ASSERT_IS_ERROR, ASSERT_VALUE_START, ASSERT_VALUE_NAMES,
    {len(model.memories)}, M_DEFAULT, M_SOURCE, Y_IS_OUTPUT, U_AFFINE
}};
"""
    (directory / "model_data.c").write_text(data)
    return guid
