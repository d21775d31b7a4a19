"""A Monte Carlo study file (TOML) as typed dataclasses, validated with errors that name the key.

    title = "..."
    runs = 200                  # samples, the nominal (sample 0) included
    seed = 20251123             # numpy Generator seed: the same seed gives the same samples
    scenarios = ["straight"]    # "straight": the paper's closed loop on Rover.fmu;
                                # "path": the lane change on SteerableRover.fmu;
                                # "straight_adapted", "path_adapted": the same with the adaptive
                                # controller (calibration, soil estimated, models identified again)
    stop_time = 20.0            # s, of the straight run (the paper's 20 s; shorter for quick looks)
    path_stop_time = 35.363     # s, of the path run (default: until the reference reaches the end)
    soil = "paper"              # the nominal soil and wheel: the ones the model was identified on
    wheel = "paper"

    [parameters."soil.c"]       # soil.<field> / wheel.<field> as `--set` takes them (SI, or *_deg),
    distribution = "lognormal"  # or an FMU parameter such as rover.M [kg]
    median = 800.0              # lognormal: median and sigma (standard deviation of ln x)
    sigma = 0.9
    lower = 100.0               # optional bounds: the distribution truncated to [lower, upper]
    upper = 3000.0

    [calibration]               # optional, of "straight_adapted" (control.adaptive.Calibration)
    duration = 3.0              # s, the calibration phase (also the start of the "after calibration" RMS)
    segment = 0.25              # s, each excitation level
    amplitude = 20.0            # N·m, the excitation torque
    sinkage_sensor = false      # the rover measures its wheels' sinkage
    optional_parameters = false # the soil estimate also tries a1, a0, lambda (several times slower)

    [correlation]               # optional: the correlation of the parameters' normal scores
    parameters = ["soil.kc", "soil.kphi"]
    matrix = [[1.0, 0.5], [0.5, 1.0]]

Distributions: ``uniform`` (lower, upper), ``normal`` (mean, std), ``lognormal`` (median, sigma),
the last two optionally truncated to [lower, upper]. Correlation acts through a Gaussian copula
(sampling.py): the matrix is the correlation of the standard-normal scores, so the samples'
Spearman rank correlation is (6/pi) asin(rho/2), within 0.02 of rho.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import Any

import numpy as np

from rover_cosim.control.calibration import Calibration
from rover_cosim.terramechanics import Soil, Wheel, library
from rover_cosim.terramechanics.library import DEGREES

from .scenarios import ADAPTIVE_VARIANT, RUN_SCENARIOS

#: Scenarios a study can run (``scenarios.RUN_SCENARIOS``): "straight" (paper Sec. 4, Rover.fmu),
#: "path" (lane change, SteerableRover.fmu), and each with the adaptive controller ("straight_adapted",
#: "path_adapted").
SCENARIOS = tuple(RUN_SCENARIOS)
#: The scenario ``--adapt`` adds beside each that has an adaptive variant.
ADAPTED = ADAPTIVE_VARIANT
#: Shipped studies (``--study NAME`` or a file).
STUDIES = Path(__file__).with_name("studies")
KINDS = {"uniform": ("lower", "upper"), "normal": ("mean", "std"), "lognormal": ("median", "sigma")}
#: The most runs a study may ask for (a million 20 s runs: ~40 days of one core).
MAX_RUNS = 1_000_000
TOP_KEYS = {"title", "source", "runs", "seed", "scenarios", "stop_time", "path_stop_time", "soil", "wheel",
            "parameters", "correlation", "calibration"}


class StudyError(ValueError):
    """A study file that cannot be used; the message names the file, the key and what was expected."""


@dataclass(frozen=True)
class Distribution:
    """One uncertain parameter: ``kind`` uniform/normal/lognormal with its two numbers ``a``, ``b``
    (lower/upper, mean/std, median/sigma of ln) and the truncation bounds (None: unbounded)."""

    name: str
    kind: str
    a: float
    b: float
    lower: float | None = None
    upper: float | None = None
    unit: str = ""

    def bounds(self) -> tuple[float, float]:
        """The support [lower, upper] (infinite where unbounded)."""
        if self.kind == "uniform":
            return self.a, self.b
        low = -math.inf if self.lower is None else self.lower
        return (max(low, 0.0) if self.kind == "lognormal" else low), (math.inf if self.upper is None else self.upper)


@dataclass(frozen=True)
class Study:
    """A study: its distributions, correlation, number of runs and seed, the scenarios and their
    stop times, and the nominal soil and wheel (library names or files)."""

    title: str
    runs: int
    seed: int
    parameters: tuple[Distribution, ...]
    correlation: np.ndarray = field(compare=False)     # (d, d) over ``parameters``, in their order
    scenarios: tuple[str, ...] = ("straight",)
    stop_time: float = 20.0                           # s, the straight run
    path_stop_time: float | None = None               # s, the path run (None: to the path's end)
    soil: str = "paper"
    wheel: str = "paper"
    source: str = ""
    path: Path | None = None
    calibration: Calibration = Calibration()

    @property
    def names(self) -> list[str]:
        return [p.name for p in self.parameters]

    def stop_time_of(self, scenario: str) -> float:
        """s: how long a run of ``scenario`` lasts (the path's: until its reference reaches the end)."""
        return RUN_SCENARIOS[scenario].stop_time(self.stop_time, self.path_stop_time)

    def check_calibration(self) -> None:
        """StudyError unless every adapted scenario's run lasts longer than its calibration."""
        for scenario in self.scenarios:
            if scenario in ADAPTED.values() and not self.stop_time_of(scenario) > self.calibration.duration:
                raise StudyError(f"{self.path or 'study'}: {scenario}: a run of {self.stop_time_of(scenario)!r} s: "
                                 f"an adapted run needs more than its calibration ({self.calibration.duration!r} s)")

    def adapted(self) -> Study:
        """The study with each scenario's adaptive variant beside it (``--adapt``)."""
        extra = [ADAPTED[s] for s in self.scenarios if s in ADAPTED]
        return replace(self, scenarios=tuple(dict.fromkeys([*self.scenarios, *extra])))

    def settings(self) -> dict[str, Any]:
        """What the study is, as JSON-able values (for summary.json)."""
        return {"title": self.title, "runs": self.runs, "seed": self.seed, "scenarios": list(self.scenarios),
                "stop_time_s": self.stop_time,
                "path_stop_time_s": self.path_stop_time, "soil": self.soil, "wheel": self.wheel, "file": str(self.path),
                "parameters": [vars(p) for p in self.parameters], "correlation": self.correlation.tolist(),
                "calibration": asdict(self.calibration)}


def _number(where: str, key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise StudyError(f"{where}: {key} = {value!r}: expected a finite number")
    return float(value)


def _check_name(where: str, name: str) -> None:
    kind, _, key = name.partition(".")
    allowed = {"soil": {f.name for f in fields(Soil)} | set(DEGREES), "wheel": {f.name for f in fields(Wheel)}}
    if not key:
        raise StudyError(f"{where}: expected soil.NAME, wheel.NAME or an FMU parameter such as rover.M")
    if kind in allowed and key not in allowed[kind]:
        raise StudyError(f"{where}: {kind} has no parameter {key!r}; "
                         f"expected one of {', '.join(sorted(allowed[kind]))}")


def _distribution(where: str, name: str, table: Any) -> Distribution:
    if not isinstance(table, dict):
        raise StudyError(f"{where}: expected a table with distribution = uniform, normal or lognormal")
    _check_name(where, name)
    kind = table.get("distribution")
    if not isinstance(kind, str) or kind not in KINDS:
        raise StudyError(f"{where}: distribution = {kind!r}: expected one of {', '.join(KINDS)}")
    known = {"distribution", "lower", "upper", "unit", "note", *KINDS[kind]}
    unknown = sorted(set(table) - known)
    if unknown:
        raise StudyError(f"{where}: unknown key(s) {unknown} for a {kind} distribution; expected {sorted(known)}")
    first, second = KINDS[kind]
    missing = [k for k in (first, second) if k not in table]
    if missing:
        raise StudyError(f"{where}: a {kind} distribution needs {first} and {second}; {', '.join(missing)} missing")
    a, b = _number(where, first, table[first]), _number(where, second, table[second])
    lower = _number(where, "lower", table["lower"]) if "lower" in table and kind != "uniform" else None
    upper = _number(where, "upper", table["upper"]) if "upper" in table and kind != "uniform" else None
    if kind == "uniform" and not a < b:
        raise StudyError(f"{where}: lower = {a!r} >= upper = {b!r}: expected lower < upper")
    if kind in ("normal", "lognormal") and not b > 0:
        raise StudyError(f"{where}: {second} = {b!r}: expected > 0")
    if kind == "lognormal" and not a > 0:
        raise StudyError(f"{where}: median = {a!r}: expected > 0 (a log-normal value is positive)")
    if lower is not None and upper is not None and not lower < upper:
        raise StudyError(f"{where}: lower = {lower!r} >= upper = {upper!r}: expected lower < upper")
    if kind == "lognormal" and upper is not None and upper <= 0:
        raise StudyError(f"{where}: upper = {upper!r}: expected > 0 for a log-normal distribution")
    return Distribution(name, kind, a, b, lower, upper, str(table.get("unit", "")))


def _correlation(where: str, table: Any, names: list[str]) -> np.ndarray:
    matrix = np.eye(len(names))
    if table is None:
        return matrix
    if not isinstance(table, dict) or set(table) != {"parameters", "matrix"}:
        raise StudyError(f"{where}: expected a table with parameters = [names] and matrix = [[...], ...]")
    chosen = table["parameters"]
    if not isinstance(chosen, list) or not all(isinstance(n, str) for n in chosen) \
            or len(set(chosen)) != len(chosen) or not chosen:
        raise StudyError(f"{where}: parameters = {chosen!r}: expected a list of distinct parameter names")
    unknown = [n for n in chosen if n not in names]
    if unknown:
        raise StudyError(f"{where}: {unknown[0]!r} is not a parameter of the study (has {', '.join(names)})")
    try:
        given = np.array(table["matrix"], dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise StudyError(f"{where}: matrix = {table['matrix']!r}: expected a square table of numbers") from None
    k = len(chosen)
    if given.shape != (k, k) or not np.all(np.isfinite(given)):
        raise StudyError(f"{where}: matrix of shape {given.shape}: expected {k} x {k} finite numbers (one row "
                         "and column per name in parameters)")
    if not np.allclose(np.diag(given), 1.0) or not np.allclose(given, given.T) or np.any(np.abs(given) > 1):
        raise StudyError(f"{where}: matrix = {given.tolist()}: expected a symmetric matrix with ones on the "
                         "diagonal and entries in [-1, 1]")
    index = [names.index(n) for n in chosen]
    matrix[np.ix_(index, index)] = given
    smallest = float(np.linalg.eigvalsh(matrix).min())
    if smallest <= 1e-10:
        raise StudyError(f"{where}: matrix = {given.tolist()} is not positive definite (smallest eigenvalue "
                         f"{smallest:.3g}): expected a valid correlation matrix")
    return matrix


def _calibration(where: str, table: Any) -> Calibration:
    """The [calibration] table (keys of control.adaptive.Calibration); errors name the key."""
    names = {f.name for f in fields(Calibration)}
    if not isinstance(table, dict) or set(table) - names:
        raise StudyError(f"{where}: calibration = {table!r}: expected a table of {', '.join(sorted(names))}")
    switches: dict[str, Any] = {}
    for key in ("sinkage_sensor", "optional_parameters"):
        switches[key] = table.get(key, False)
        if not isinstance(switches[key], bool):
            raise StudyError(f"{where}: calibration.{key} = {switches[key]!r}: expected true or false")
    numbers: dict[str, Any] = {k: _number(where, f"calibration.{k}", v) for k, v in table.items() if k not in switches}
    try:
        return Calibration(**numbers, **switches)
    except ValueError as error:
        raise StudyError(f"{where}: {error}") from None


def _check_library(where: str, kind: str, value: Any) -> None:
    """The nominal soil or wheel: a name of the library or a TOML file, known before any work."""
    if not isinstance(value, str):
        raise StudyError(f"{where}: {kind} = {value!r}: expected the name of a {kind} of the library or a TOML file")
    try:
        library.entry(kind, value)
    except ValueError as error:
        raise StudyError(f"{where}: {kind} = {value!r}: {error}") from None


def _top(where: str, data: dict[str, Any]) -> dict[str, Any]:
    unknown = sorted(set(data) - TOP_KEYS)
    if unknown:
        raise StudyError(f"{where}: unknown key(s) {unknown}; expected {', '.join(sorted(TOP_KEYS))}")
    runs, seed = data.get("runs"), data.get("seed")
    if isinstance(runs, bool) or not isinstance(runs, int) or not 1 <= runs <= MAX_RUNS:
        raise StudyError(f"{where}: runs = {runs!r}: expected a whole number from 1 (the nominal included) to "
                         f"{MAX_RUNS:,} (~3.5 s of a core each)")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise StudyError(f"{where}: seed = {seed!r}: expected a whole number >= 0")
    scenarios = data.get("scenarios", ["straight"])
    if not isinstance(scenarios, list) or not scenarios or any(s not in SCENARIOS for s in scenarios):
        raise StudyError(f"{where}: scenarios = {scenarios!r}: expected a list of {', '.join(SCENARIOS)}")
    stop_time = _number(where, "stop_time", data.get("stop_time", 20.0))
    if not 0.01 <= stop_time <= 600:
        raise StudyError(f"{where}: stop_time = {stop_time!r} s: expected 0.01 .. 600 s")
    path_stop_time = data.get("path_stop_time")
    if path_stop_time is not None:
        path_stop_time = _number(where, "path_stop_time", path_stop_time)
        if not 0.01 <= path_stop_time <= 600:
            raise StudyError(f"{where}: path_stop_time = {path_stop_time!r} s: expected 0.01 .. 600 s")
    for kind in ("soil", "wheel"):
        _check_library(where, kind, data.get(kind, "paper"))
    return {"runs": runs, "seed": seed, "scenarios": tuple(dict.fromkeys(scenarios)), "stop_time": stop_time,
            "path_stop_time": path_stop_time, "calibration": _calibration(where, data.get("calibration", {})),
            "title": str(data.get("title", "")), "source": str(data.get("source", "")),
            "soil": str(data.get("soil", "paper")), "wheel": str(data.get("wheel", "paper"))}


def parse_study(data: dict[str, Any], where: str = "study") -> Study:
    """The study of a TOML document's tables (``where`` names it in errors)."""
    top = _top(where, data)
    tables = data.get("parameters")
    if not isinstance(tables, dict) or not tables:
        raise StudyError(f"{where}: expected at least one [parameters.\"NAME\"] table")
    parameters = tuple(_distribution(f"{where}: parameters.{name!r}", name, table) for name, table in tables.items())
    names = [p.name for p in parameters]
    clashes = [n for n in names if n.startswith("soil.") and n.split(".")[1] in DEGREES
               and f"soil.{DEGREES[n.split('.')[1]]}" in names]
    if clashes:
        raise StudyError(f"{where}: both {clashes[0]} and soil.{DEGREES[clashes[0].split('.')[1]]} given: expected one")
    correlation = _correlation(f"{where}: correlation", data.get("correlation"), names)
    return Study(parameters=parameters, correlation=correlation, **top)


def load_study(spec: str | Path, runs: int | None = None, seed: int | None = None) -> Study:
    """The study of a TOML file, or of a shipped study by name (``lunar_regolith``), with the
    command line's overrides of the number of runs and the seed."""
    path = Path(spec)
    if not path.is_file() and (STUDIES / f"{spec}.toml").is_file():
        path = STUDIES / f"{spec}.toml"
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        shipped = ", ".join(p.stem for p in sorted(STUDIES.glob("*.toml")))
        raise StudyError(f"study {str(spec)!r}: no such file; expected a TOML file or one of {shipped}") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError, IsADirectoryError) as error:
        raise StudyError(f"{path}: not a readable TOML file ({error})") from None
    if runs is not None:
        data["runs"] = runs
    if seed is not None:
        data["seed"] = seed
    study = parse_study(data, str(path))
    return replace(study, path=path)
