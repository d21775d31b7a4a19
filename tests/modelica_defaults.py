"""Defaults of the Modelica library the tests compare against (one source of truth: the .mo files)."""

from __future__ import annotations

import re
from pathlib import Path

_WHEEL = Path(__file__).resolve().parent.parent / "modelica" / "RoverTerramechanics" / "Components" / "RigidWheel.mo"

#: The FMUs' Gauss-Legendre nodes per piece of the contact patch: the Modelica wheel's nNodes.
FMU_NODES = int(re.search(r"parameter Integer nNodes = (\d+)", _WHEEL.read_text()).group(1))  # type: ignore[union-attr]
