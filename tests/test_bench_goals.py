"""``make bench``'s goals (issue 49): bench_pipeline turns the stages it timed into a table of goals
(measured, the baseline commit's, the goal, met or not), and the generated Benchmarks page shows it."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _module(path: Path, name: str):  # noqa: ANN202 - a module loaded from a file
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def test_the_goals_say_what_was_measured_against_what_and_whether_it_is_met():
    bench = _module(ROOT / "benchmarks" / "bench_pipeline.py", "bench_pipeline_under_test")
    results = {"simulate": {"closed_loop_real_time_factor": 12.9, "baseline": {"closed_loop_real_time_factor": 12.0}},
               "montecarlo, 2 workers": {"runs_per_minute": 310.0},
               "build-fmus": {"wall_seconds": 25.0}}
    rows = {row["goal"].split(":")[0]: row for row in bench.goals(results)}
    closed = rows["closed loop, 20 s on Rover.fmu"]
    assert (closed["measured"], closed["baseline"], closed["target"], closed["met"]) == (12.9, 12.0, ">= 50", False)
    assert rows["Monte Carlo, 2 workers"]["met"] is True
    built = rows["six FMUs built (host only)"]
    assert built["met"] is False and built["target"] == "<= 20"
    assert rows["simulate --only path, whole command"]["met"] is None  # not run: not measured, not "not met"
    assert len(rows) == len(bench.GOALS)


def test_the_benchmarks_page_shows_the_goals_table(tmp_path, monkeypatch):
    (tmp_path / "bench").mkdir()
    record = {"created_utc": "2026-12-06T00:00:00Z", "git_commit": "abc", "results": {"fig3": {"wall_seconds": 3.0}},
              "goals": [{"goal": "closed loop", "measured": 12.9, "baseline": None, "target": ">= 50", "met": False}]}
    (tmp_path / "bench" / "pipeline.json").write_text(json.dumps(record))
    monkeypatch.setenv("ROVER_COSIM_DOCS_RESULTS", str(tmp_path))
    hooks = _module(ROOT / "docs" / "hooks.py", "docs_hooks_under_test")
    page = hooks.benchmarks_page()
    assert "| closed loop | 12.9 | - | >= 50 | not met |" in page
    assert "| fig3.wall_seconds | 3 |" in page
