"""Inputs the derivatives are affine in (issue 49: fewer evaluations per step): the exporter marks
them (a motor torque; not a load, a speed or a soil share), and the Co-Simulation runtime updates
the derivatives it has for their change instead of evaluating the model again at the next step's
start; an input set to the bits it has changes nothing, and inputs interpolated over a step end it
where the next step's values begin, so ramped set-points keep the derivatives too. Checked against
the same FMU made to evaluate again (a tunable solver parameter set to its own value with each
torque): the same trajectory to rounding, an evaluation fewer per step, the counter says so; a
restored FMU state repeats a run exactly."""

from __future__ import annotations

import math
from pathlib import Path

import fmpy
import numpy as np
import pytest
from cs_slave import Slave

from rover_cosim.fmubuild import codegen, ode, source

STEP, STEPS = 1e-3, 1500


def test_the_exporter_marks_the_torques_and_nothing_the_contact_reads():
    model = ode.translate(source.load(source.fmu_class("Rover")), "Rover")
    flags = codegen.affine_inputs(model)
    described = [v.name for v in codegen.layout(model).variables if v.kind == "input"]
    assert len(flags) == len(described)
    assert {name for name, flag in zip(described, flags) if flag} == {f"tau[{i}]" for i in range(1, 7)}, described


class _Rover(Slave):
    """Rover.fmu (Co-Simulation) stepped with torques that change every step."""

    watching: tuple[str, ...] = ("x", "v", "omega[1]", "omega[4]", "pitch")

    def __init__(self, fmu: Path, tmp: Path):
        super().__init__(fmu, tmp, "r")
        self.taus = [self.refs[f"tau[{i}]"] for i in range(1, 7)]
        self.watched = [self.refs[n] for n in self.watching]

    def run(self, first: int, last: int, evaluate_again: bool, own_values: bool = False) -> np.ndarray:
        """Steps ``first`` to ``last`` with the inputs of :meth:`set_inputs`; ``evaluate_again``: a
        tunable solver parameter set to its own value with them (the derivatives are evaluated
        again); ``own_values``: a non-affine input (a rut depth) set to the bits it has."""
        rows = []
        for k in range(first, last):
            t = k * STEP
            self.set_inputs(k, t)
            if own_values:
                share = self.refs["rutDepth[1]"]
                self.slave.setReal([share], self.slave.getReal([share]))
            if evaluate_again:
                self.slave.setReal([self.refs["solver.maxStep"]], self.slave.getReal([self.refs["solver.maxStep"]]))
            self.slave.doStep(t, STEP)
            rows.append(self.slave.getReal(self.watched))
        return np.array(rows)

    def set_inputs(self, k: int, t: float) -> None:
        """Step ``k``'s inputs: torques that change every step."""
        torque = 40.0 + 15.0 * math.sin(7.0 * t) + 0.01 * k
        self.slave.setReal(self.taus, [torque, torque, torque, torque * 0.9, torque * 0.9, torque * 0.9])


def test_updated_derivatives_follow_the_evaluated_ones_to_rounding_with_an_evaluation_fewer_per_step(fmus, tmp_path):
    updated, evaluated = _Rover(fmus["Rover"], tmp_path / "a"), _Rover(fmus["Rover"], tmp_path / "b")
    try:
        fast, slow = updated.run(0, STEPS, False), evaluated.run(0, STEPS, True)
        assert fast[-1, 1] > 0.1  # it drove off
        scale = np.abs(slow).max(axis=0)
        assert np.all(np.abs(fast - slow).max(axis=0) <= 1e-9 * scale), np.abs(fast - slow).max(axis=0) / scale
        assert updated.statistic("derivativeUpdates") >= STEPS - 2 and evaluated.statistic("derivativeUpdates") == 0
        saved = evaluated.statistic("evaluations") - updated.statistic("evaluations")
        assert saved >= 0.9 * STEPS, (updated.statistic("evaluations"), evaluated.statistic("evaluations"))
    finally:
        updated.close()
        evaluated.close()


def test_an_input_set_to_the_bits_it_has_changes_nothing(fmus, tmp_path):
    plain, again = _Rover(fmus["Rover"], tmp_path / "a"), _Rover(fmus["Rover"], tmp_path / "b")
    try:
        np.testing.assert_array_equal(plain.run(0, 300, False), again.run(0, 300, False, own_values=True))
        for name in ("evaluations", "derivativeUpdates"):
            assert plain.statistic(name) == again.statistic(name), name
    finally:
        plain.close()
        again.close()


class _Steering(_Rover):
    """SteerableRover.fmu with its wheels' steering set-points ramped over each step as the
    interpolating master gives them (the value at the step's start and the slope to its end): the
    torques' gain reads the steering (a turned wheel's reaction), which moves within every step."""

    watching = ("x", "y", "yaw", "v", "omega[1]", "omega[3]")

    def __init__(self, fmu: Path, tmp: Path):
        super().__init__(fmu, tmp)
        self.steers = [self.refs[f"steer[{i}]"] for i in range(1, 7)]

    @staticmethod
    def steering(k: int) -> list[float]:
        front = 0.3 * math.sin(3.0 * k * STEP)
        return [front, 0.0, -front, front, 0.0, -front]

    def set_inputs(self, k: int, t: float) -> None:
        """Step ``k``'s inputs: the steering at the step's start with its slope to the end, and
        torques that change every step."""
        torque = 40.0 + 15.0 * math.sin(7.0 * t)
        start, end = self.steering(k), self.steering(k + 1)
        self.slave.setReal(self.steers, start)
        self.slave.setRealInputDerivatives(self.steers, [1] * 6, [(b - a) / STEP for a, b in zip(start, end)])
        self.slave.setReal(self.taus, [torque, torque * 1.1, torque, torque * 0.9, torque, torque * 0.8])


def test_ramped_set_points_keep_the_derivatives_and_the_gain_follows_them(fmus, tmp_path):
    kept, evaluated = _Steering(fmus["SteerableRover"], tmp_path / "a"), _Steering(fmus["SteerableRover"],
                                                                                   tmp_path / "b")
    try:
        fast, slow = kept.run(0, STEPS, False), evaluated.run(0, STEPS, True)
        assert fast[-1, 3] > 0.1 and np.abs(fast[:, 2]).max() > 1e-3  # it drove off and turned
        scale = np.abs(slow).max(axis=0)
        assert np.all(np.abs(fast - slow).max(axis=0) <= 1e-9 * scale), np.abs(fast - slow).max(axis=0) / scale
        assert kept.statistic("derivativeUpdates") >= 0.9 * STEPS and evaluated.statistic("derivativeUpdates") == 0
        saved = evaluated.statistic("evaluations") - kept.statistic("evaluations")
        assert saved >= 0.9 * STEPS, (kept.statistic("evaluations"), evaluated.statistic("evaluations"))
    finally:
        kept.close()
        evaluated.close()


def test_a_restored_state_repeats_a_run_of_updated_derivatives_exactly(fmus, tmp_path):
    rover = _Rover(fmus["Rover"], tmp_path)
    try:
        rover.run(0, 200, False)
        state = rover.slave.getFMUstate()
        first = rover.run(200, 400, False)
        rover.slave.setFMUstate(state)
        again = rover.run(200, 400, False)
        np.testing.assert_array_equal(first, again)
        rover.slave.freeFMUstate(state)
    finally:
        rover.close()


@pytest.mark.parametrize("name", ["Wheel", "SteerableRover", "LegWheelRover"])
def test_the_wheels_torque_is_marked_in_every_fmu_that_takes_one(fmus, name):
    """The generated layout (model_data.c) marks each motor torque input, and no other."""
    import zipfile

    with zipfile.ZipFile(fmus[name]) as archive:
        data = archive.read("sources/model_data.c").decode()
    flags = [int(v) for v in data.split("U_AFFINE[] = {")[1].split("}")[0].split(",")]
    inputs = [v.name for v in fmpy.read_model_description(str(fmus[name])).modelVariables if v.causality == "input"]
    assert {n for n, f in zip(inputs, flags) if f} == {n for n in inputs if n.startswith("tau")}
