"""The FMI 2.0 runtime's logging categories, FMU states, input derivatives and reset (issue 31,
part 5): each defect the issue measured, as a host meets it."""

from __future__ import annotations

import ctypes
from pathlib import Path

import fmpy
import pytest
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Model, FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.fmi2 import defaultCallbacks as default_callbacks


class Messages:
    """A logger that keeps (category, text) of every message; alive as long as the instance."""

    def __init__(self) -> None:
        self.seen: list[tuple[str, str]] = []
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(self._log)
        self.callbacks.allocateMemory = default_callbacks.allocateMemory
        self.callbacks.freeMemory = default_callbacks.freeMemory

    def _log(self, env, name, status, category, text) -> None:  # noqa: ANN001 - ctypes callback
        self.seen.append((category.decode(), text.decode()))

    def categories(self) -> set[str]:
        return {category for category, _ in self.seen}


def instance(fmus, tmp_path: Path, kind: str = "CS", *, logging: bool = False, start: float = 0.0,
             values: dict[str, float] | None = None, initialize: bool = True, name: str = "SingleWheel"):
    md = fmpy.read_model_description(fmus[name])
    folder = fmpy.extract(str(fmus[name]), unzipdir=str(tmp_path / f"{name}-{kind}"))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    messages = Messages()
    cls = FMU2Slave if kind == "CS" else FMU2Model
    fmu = cls(guid=md.guid, unzipDirectory=folder, modelIdentifier=name, instanceName=kind)
    fmu.instantiate(callbacks=messages.callbacks, loggingOn=logging)
    fmu.setupExperiment(startTime=start)
    values = {"W": 575.0, "tau": 20.0} if values is None else values
    fmu.setReal([refs[k] for k in values], list(values.values()))
    if initialize:
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
    return fmu, refs, messages


def _set_debug_logging(fmu, on: bool, categories: list[str]) -> int:
    array = (ctypes.c_char_p * len(categories))(*[c.encode() for c in categories])
    function = fmu.dll.fmi2SetDebugLogging
    function.restype = ctypes.c_int
    return function(fmu.component, int(on), ctypes.c_size_t(len(categories)), array)


def _run_and_terminate(fmu, steps: int = 20) -> None:
    for k in range(steps):
        fmu.doStep(k * 1e-3, 1e-3)
    fmu.terminate()


def test_logging_follows_the_categories_asked_for(fmus, tmp_path):
    """Only logStatusError asked for: no statistics at fmi2Terminate (they came before); all
    categories (none named): the statistics come; an unknown category is an error naming it."""
    fmu, _, messages = instance(fmus, tmp_path / "a", logging=True)
    assert _set_debug_logging(fmu, True, ["logStatusError"]) == 0
    _run_and_terminate(fmu)
    assert "logStatistics" not in messages.categories()
    fmu.freeInstance()

    fmu, _, messages = instance(fmus, tmp_path / "b", logging=False)
    assert _set_debug_logging(fmu, True, []) == 0
    _run_and_terminate(fmu)
    assert "logStatistics" in messages.categories()
    fmu.freeInstance()

    fmu, _, messages = instance(fmus, tmp_path / "c", logging=True)
    assert _set_debug_logging(fmu, True, ["logStatistics", "logEverything"]) == 3  # fmi2Error
    assert any("logEverything" in text for _, text in messages.seen)
    assert _set_debug_logging(fmu, False, ["logStatistics"]) == 0
    _run_and_terminate(fmu)
    assert "logStatistics" not in messages.categories()
    fmu.freeInstance()


def test_a_state_is_restored_only_into_its_own_interface_kind(fmus, tmp_path):
    cs, _, cs_messages = instance(fmus, tmp_path, "CS")
    me, _, me_messages = instance(fmus, tmp_path, "ME")
    cs.doStep(0.0, 1e-3)
    saved_cs = cs.serializeFMUstate(cs.getFMUstate())
    me.enterContinuousTimeMode()
    saved_me = me.serializeFMUstate(me.getFMUstate())
    with pytest.raises(FMICallException):
        me.deSerializeFMUstate(saved_cs)
    assert any("Co-Simulation instance" in text for _, text in me_messages.seen)
    with pytest.raises(FMICallException):
        cs.deSerializeFMUstate(saved_me)
    assert any("Model Exchange instance" in text for _, text in cs_messages.seen)
    cs.setFMUstate(cs.deSerializeFMUstate(saved_cs))  # its own kind: fine
    cs.doStep(1e-3, 1e-3)
    for fmu in (cs, me):
        fmu.terminate()
        fmu.freeInstance()


def _set_input_derivative(fmu, ref: int, value: float) -> int:
    function = fmu.dll.fmi2SetRealInputDerivatives
    function.restype = ctypes.c_int
    return function(fmu.component, (ctypes.c_uint * 1)(ref), ctypes.c_size_t(1), (ctypes.c_int * 1)(1),
                    (ctypes.c_double * 1)(value))


def test_input_derivatives_set_before_initialization_start_at_the_start_time(fmus, tmp_path):
    """tau = 20 N·m with d tau/dt = 100 N·m/s set before initialization at t0 = 5 s: tau reads 20 at
    t0 (it read 520: the derivative counted from t = 0) and 21 after a 10 ms step."""
    fmu, refs, _ = instance(fmus, tmp_path, start=5.0, initialize=False)
    assert _set_input_derivative(fmu, refs["tau"], 100.0) == 0
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    assert fmu.getReal([refs["tau"]])[0] == pytest.approx(20.0, abs=1e-12)
    fmu.doStep(5.0, 0.01)
    assert fmu.getReal([refs["tau"]])[0] == pytest.approx(21.0, abs=1e-9)
    fmu.terminate()
    assert _set_input_derivative(fmu, refs["tau"], 1.0) == 3  # refused once terminated
    fmu.freeInstance()


def test_a_saved_state_keeps_the_input_derivatives_and_the_statistics(fmus, tmp_path):
    fmu, refs, _ = instance(fmus, tmp_path)
    for k in range(10):
        fmu.doStep(k * 1e-3, 1e-3)
    assert _set_input_derivative(fmu, refs["tau"], 500.0) == 0
    statistics = [refs[n] for n in ("statistics.steps", "statistics.evaluations", "statistics.jacobians")]
    saved = fmu.getFMUstate()
    counted = fmu.getReal(statistics)
    fmu.doStep(0.01, 0.01)
    first = fmu.getReal([refs["v"], refs["tau"], refs["slip"]])
    fmu.setFMUstate(saved)
    assert fmu.getReal(statistics) == counted
    fmu.doStep(0.01, 0.01)
    assert fmu.getReal([refs["v"], refs["tau"], refs["slip"]]) == first  # the derivative came back with the state
    assert first[1] == pytest.approx(25.0)
    fmu.freeFMUstate(saved)
    fmu.terminate()
    fmu.freeInstance()


def test_reset_restores_the_statistics_too(fmus, tmp_path):
    fmu, refs, _ = instance(fmus, tmp_path)
    statistics = [refs[n] for n in ("statistics.steps", "statistics.evaluations", "statistics.jacobians")]
    fresh = fmu.getReal(statistics)
    for k in range(10):
        fmu.doStep(k * 1e-3, 1e-3)
    assert fmu.getReal(statistics)[0] > 0
    fmu.reset()
    assert fmu.getReal(statistics) == [0.0, 0.0, 0.0]
    assert fresh[0] == 0.0
    fmu.freeInstance()


def test_a_step_that_does_not_advance_time_is_an_error(fmus, tmp_path):
    """At t = 1e17 s a step of 1 s leaves t where it is (t + h == t): fmi2Error with a message,
    not fmi2OK without a step."""
    fmu, _, messages = instance(fmus, tmp_path, start=1e17)
    with pytest.raises(FMICallException):
        fmu.doStep(1e17, 1.0)
    assert any("does not advance" in text for _, text in messages.seen)
    fmu.terminate()
    fmu.freeInstance()
