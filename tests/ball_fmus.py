"""Builds the bouncing-ball test FMUs from tests/fmus (ball_model.h: the equations): ``Ball2.fmu``
(FMI 2.0 Model Exchange only, ball2.c) and ``Ball3.fmu`` (FMI 3.0 Co-Simulation and Model
Exchange, ball3.c, with Float32, Int64, UInt8 and String variables); and the exact solution the
tests compare them with."""

from __future__ import annotations

import math
from pathlib import Path

import fmpy
from c_fmu import compile_fmu

G, E, H0, V_REST = 9.81, 0.7, 1.0, 0.1  # m/s2, 1, m, m/s: the FMUs' defaults (ball_model.h)

#: FMI 2.0: (name, type, value reference, causality, variability, initial, start, extra attributes)
BALL2 = [
    ("h", "Real", 0, "output", "continuous", "exact", "1", ""),
    ("der(h)", "Real", 1, "local", "continuous", "calculated", None, ' derivative="1"'),
    ("v", "Real", 2, "output", "continuous", "exact", "0", ""),
    ("der(v)", "Real", 3, "local", "continuous", "calculated", None, ' derivative="3"'),
    ("g", "Real", 4, "parameter", "fixed", "exact", "9.81", ""),
    ("e", "Real", 5, "parameter", "tunable", "exact", "0.7", ""),
    ("a", "Real", 6, "input", "continuous", None, "0", ""),
    ("tSwitch", "Real", 7, "parameter", "fixed", "exact", "0.5", ""),
    ("count", "Integer", 0, "output", "discrete", "exact", "0", ""),
    ("maxBounces", "Integer", 1, "parameter", "fixed", "exact", "0", ""),
    ("late", "Boolean", 0, "output", "discrete", "exact", "false", ""),
    ("frozen", "Boolean", 1, "input", "discrete", None, "false", ""),
]

#: FMI 3.0: (name, type, value reference, causality, variability, initial, start, extra attributes)
BALL3 = [
    ("time", "Float64", 0, "independent", "continuous", None, None, ""),
    ("h", "Float64", 1, "output", "continuous", "exact", "1", ""),
    ("der(h)", "Float64", 2, "local", "continuous", "calculated", None, ' derivative="1"'),
    ("v", "Float64", 3, "output", "continuous", "exact", "0", ""),
    ("der(v)", "Float64", 4, "local", "continuous", "calculated", None, ' derivative="3"'),
    ("g", "Float64", 5, "parameter", "fixed", "exact", "9.81", ""),
    ("e", "Float64", 6, "parameter", "tunable", "exact", "0.7", ""),
    ("a", "Float64", 7, "input", "continuous", None, "0", ""),
    ("count", "Int32", 8, "output", "discrete", "exact", "0", ""),
    ("late", "Boolean", 9, "output", "discrete", "exact", "false", ""),
    ("tSwitch", "Float64", 10, "parameter", "fixed", "exact", "0.5", ""),
    ("maxBounces", "Int32", 11, "parameter", "fixed", "exact", "0", ""),
    ("h32", "Float32", 12, "output", "continuous", "calculated", None, ""),
    ("count64", "Int64", 13, "output", "discrete", "calculated", None, ""),
    ("label", "String", 14, "parameter", "fixed", "exact", "ball", ""),
    ("tag", "String", 15, "output", "discrete", "calculated", None, ""),
    ("gainU8", "UInt8", 16, "parameter", "fixed", "exact", "3", ""),
    ("countU8", "UInt8", 17, "output", "discrete", "calculated", None, ""),
    ("z", "Float64", 18, "local", "continuous", "calculated", None, ""),
]


def _ball2_description() -> str:
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             '<fmiModelDescription fmiVersion="2.0" modelName="Ball2" guid="{ball2-rover-cosim-tests}" '
             'variableNamingConvention="structured" numberOfEventIndicators="1">',
             '  <ModelExchange modelIdentifier="Ball2" canGetAndSetFMUstate="true"/>',
             '  <DefaultExperiment startTime="0" stopTime="3" stepSize="0.01"/>', "  <ModelVariables>"]
    for name, kind, reference, causality, variability, initial, start, extra in BALL2:
        attributes = f' initial="{initial}"' if initial and causality != "input" else ""
        value = f' start="{start}"' if start is not None else ""
        lines.append(f'    <ScalarVariable name="{name}" valueReference="{reference}" causality="{causality}" '
                     f'variability="{variability}"{attributes}><{kind}{value}{extra}/></ScalarVariable>')
    index = {row[0]: i for i, row in enumerate(BALL2, start=1)}
    lines += ["  </ModelVariables>", "  <ModelStructure>", "    <Outputs>"]
    lines += [f'      <Unknown index="{index[n]}" dependencies=""/>' for n in ("h", "v", "count", "late")]
    lines += ["    </Outputs>", "    <Derivatives>"]
    lines += [f'      <Unknown index="{index["der(h)"]}" dependencies="{index["v"]} {index["frozen"]}"/>',
              f'      <Unknown index="{index["der(v)"]}" dependencies="{index["a"]} {index["frozen"]}"/>']
    lines += ["    </Derivatives>", "    <InitialUnknowns>"]
    lines += [f'      <Unknown index="{index[n]}"/>' for n in ("der(h)", "der(v)")]
    lines += ["    </InitialUnknowns>", "  </ModelStructure>", "</fmiModelDescription>", ""]
    return "\n".join(lines)


def _ball3_description() -> str:
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             '<fmiModelDescription fmiVersion="3.0" modelName="Ball3" instantiationToken="{ball3-rover-cosim-tests}" '
             'variableNamingConvention="structured">',
             '  <ModelExchange modelIdentifier="Ball3" canGetAndSetFMUState="true"/>',
             '  <CoSimulation modelIdentifier="Ball3" canGetAndSetFMUState="true" '
             'canHandleVariableCommunicationStepSize="true" hasEventMode="false"/>',
             '  <DefaultExperiment startTime="0" stopTime="3" stepSize="0.01"/>', "  <ModelVariables>"]
    for name, kind, reference, causality, variability, initial, start, extra in BALL3:
        attributes = f' initial="{initial}"' if initial and causality not in ("input", "independent") else ""
        value = ""
        if start is not None:
            value = f' start="{start}"'
        if kind == "String":
            inner = f'<Start value="{start}"/>' if start is not None else ""
            lines.append(f'    <String name="{name}" valueReference="{reference}" causality="{causality}" '
                         f'variability="{variability}"{attributes}>{inner}</String>')
            continue
        lines.append(f'    <{kind} name="{name}" valueReference="{reference}" causality="{causality}" '
                     f'variability="{variability}"{attributes}{value}{extra}/>')
    lines += ["  </ModelVariables>", "  <ModelStructure>"]
    lines += [f'    <Output valueReference="{r}" dependencies=""/>' for r in (1, 3, 8, 9, 12, 13, 15, 17)]
    lines += [f'    <ContinuousStateDerivative valueReference="{r}"/>' for r in (2, 4)]
    lines += ['    <InitialUnknown valueReference="2"/>', '    <InitialUnknown valueReference="4"/>']
    lines += ['    <EventIndicator valueReference="18"/>', "  </ModelStructure>", "</fmiModelDescription>", ""]
    return "\n".join(lines)


def build_ball2(folder: Path) -> Path | str:
    """``folder``/Ball2.fmu (FMI 2.0 Model Exchange), or why it could not be built."""
    return compile_fmu("ball2.c", "Ball2", folder, "Ball2", _ball2_description())


def build_ball3(folder: Path) -> Path | str:
    """``folder``/Ball3.fmu (FMI 3.0 Co-Simulation and Model Exchange), or why it could not be built."""
    return compile_fmu("ball3.c", "Ball3", folder, "Ball3", _ball3_description(), platform=fmpy.platform_tuple)


def exact_height(t: float, h0: float = H0, g: float = G, e: float = E) -> tuple[float, int]:
    """(height [m], bounces so far) of the ball dropped from rest at ``h0`` at time ``t`` [s], from
    the free flights between bounces (a bounce slower than V_REST leaves it resting)."""
    now, h, v, count = 0.0, h0, 0.0, 0
    while True:
        impact = (v + math.sqrt(v * v + 2 * g * h)) / g  # h + v s - g s^2 / 2 = 0
        if now + impact > t:
            s = t - now
            return h + v * s - 0.5 * g * s * s, count
        now += impact
        count += 1
        v = e * (g * impact - v)  # the impact speed, reversed and scaled
        h = 0.0
        if v < V_REST:
            return 0.0, count
