"""Shared fixtures: the FMUs of `make fmus`, built once per test session."""

from __future__ import annotations

from pathlib import Path

import pytest

from fmubuild import build

FMU_DIR = Path(__file__).resolve().parent.parent / "fmus"


@pytest.fixture(scope="session")
def fmus() -> dict[str, Path]:
    """The four FMUs, built into fmus/ as `make fmus` does (skipped when up to date)."""
    results = build.build_all(build.FMU_MODELS, FMU_DIR, backend="builtin")
    return {r.name: r.path for r in results}
