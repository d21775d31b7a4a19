"""Steady-state single-wheel test-bed data: the typed record :class:`TestBedData`, its CSV file
(:func:`read_testbed_csv`, :meth:`TestBedData.to_csv`), data generated from the numpy reference
wheel with seeded noise (:func:`generate_testbed_data`), the wheel's prediction at the same
inputs (:func:`predict`) and the prediction error of a model against data
(:func:`prediction_error`).

The CSV file: one header line naming the columns, then one row per measurement. The unit is part
of a column's name: ``load_N`` (vertical load W [N], > 0) and ``slip`` (slip ratio κ [-], in
[-1, 1]) are required; ``slip_angle_deg`` (β [deg], |β| < 90; left out: 0) is optional; at least
one measured column of ``Fx_N`` (drawbar pull [N]), ``Tx_Nm`` (driving torque [N·m]),
``sinkage_m`` (sinkage [m], >= 0) and ``Fy_N`` (lateral force [N]). Blank lines and lines that
begin with ``#`` are skipped. Every value must be a finite number; a bad one is refused with a
message naming its row (data rows counted from 1 after the header), its line in the file and
its column.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rover_cosim.terramechanics import Soil, Wheel, wheel_state

FloatArray = NDArray[np.float64]

#: The inputs of a measurement (the test bed sets them) and the measured channels, with their units.
INPUTS = {"load_N": "N", "slip": "-", "slip_angle_deg": "deg"}
CHANNELS = {"Fx_N": "N", "Tx_Nm": "N·m", "sinkage_m": "m", "Fy_N": "N"}
#: Every column of the file, in the order files are written.
COLUMNS = ("load_N", "slip", "slip_angle_deg", "Fx_N", "Tx_Nm", "sinkage_m", "Fy_N")
REQUIRED = ("load_N", "slip")
#: What each channel is, for messages and figures.
LABELS = {"Fx_N": "drawbar pull Fx [N]", "Tx_Nm": "driving torque Tx [N·m]", "sinkage_m": "sinkage h [m]",
          "Fy_N": "lateral force Fy [N]"}


def _row_name(row: int, lines: Sequence[int] | None) -> str:
    """"row 3" (0-based ``row``, shown from 1), with its line in the file where known."""
    return f"row {row + 1}" + (f" (line {lines[row]})" if lines is not None else "")


#: N, the largest wheel load a measurement may give (a thousand times a rover's wheel).
MAX_LOAD = 1e6
#: Per column: (test of a value, what is expected) beyond being a finite number.
_RANGES: dict[str, tuple[Callable[[FloatArray], NDArray[np.bool_]], str]] = {
    "load_N": (lambda v: (v > 0) & (v <= MAX_LOAD), f"a load > 0 N and at most {MAX_LOAD:g} N"),
    "slip": (lambda v: np.abs(v) <= 1, "a slip ratio in [-1, 1]"),
    "slip_angle_deg": (lambda v: np.abs(v) < 90, "a slip angle in (-90, 90) deg"),
    "sinkage_m": (lambda v: v >= 0, "a sinkage >= 0 m"),
}


def check_values(columns: Mapping[str, FloatArray], lines: Sequence[int] | None = None, source: str = "data") -> None:
    """ValueError naming the first bad value's row, line and column: not finite, or outside its
    column's range (load > 0 N, slip in [-1, 1], |slip angle| < 90 deg, sinkage >= 0 m)."""
    for name, values in columns.items():
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            row = int(bad[0])
            raise ValueError(f"{source}: {_row_name(row, lines)}, column {name}: {float(values[row])!r} is not a "
                             "finite number")
        if name in _RANGES:
            test, expected = _RANGES[name]
            bad = np.flatnonzero(~test(values))
            if bad.size:
                row = int(bad[0])
                unit = INPUTS.get(name, CHANNELS.get(name, ""))
                shown = f"{float(values[row])!r}" + ("" if unit == "-" else f" {unit}")
                raise ValueError(f"{source}: {_row_name(row, lines)}, column {name}: {shown}: expected {expected}")


def _array(value: ArrayLike | None) -> FloatArray | None:
    if value is None:
        return None
    array = np.array(value, dtype=float).ravel()
    array.flags.writeable = False
    return array


@dataclass(frozen=True, eq=False)
class TestBedData:
    """Steady-state single-wheel measurements, one element per row (SI units as in the column
    names). ``load_N`` and ``slip`` are required; a measured channel left out is None.

    Attributes:
        load_N: vertical wheel load W [N], each > 0.
        slip: slip ratio κ [-], each in [-1, 1].
        Fx_N: drawbar pull Fx [N] (the soil's force along the heading), or None.
        Tx_Nm: driving torque Tx [N·m] (the axle torque that holds the wheel at its slip), or None.
        sinkage_m: sinkage h [m], each >= 0, or None.
        slip_angle_deg: slip angle β [deg], |β| < 90; None: 0 for every row.
        Fy_N: lateral force Fy [N] (the soil's force along the wheel's left), or None.
        source: where the data came from (a file name), for messages.
        lines: the line of each row in its file (messages name them), or None.
    """

    __test__ = False  # not a pytest test class, whatever its name

    load_N: FloatArray
    slip: FloatArray
    Fx_N: FloatArray | None = None
    Tx_Nm: FloatArray | None = None
    sinkage_m: FloatArray | None = None
    slip_angle_deg: FloatArray | None = None
    Fy_N: FloatArray | None = None
    source: str = "data"
    lines: tuple[int, ...] | None = None

    def __post_init__(self) -> None:
        for f in fields(self):
            if f.name not in ("source", "lines"):
                object.__setattr__(self, f.name, _array(getattr(self, f.name)))
        if self.lines is not None and len(self.lines) != len(self.load_N):
            raise ValueError(f"{self.source}: {len(self.lines)} line numbers for {len(self.load_N)} rows")
        sizes = {name: len(values) for name, values in self.columns().items()}
        if len(set(sizes.values())) > 1:
            raise ValueError(f"{self.source}: columns of different lengths: "
                             + ", ".join(f"{k} {v}" for k, v in sizes.items()))
        if not self.rows:
            raise ValueError(f"{self.source}: no data rows")
        if not self.channels:
            raise ValueError(f"{self.source}: no measured column: expected at least one of {', '.join(CHANNELS)}")
        check_values(self.columns(), self.lines, self.source)

    def row_name(self, row: int) -> str:
        """"row 3 (line 5)": how messages name row ``row`` (0-based) of the data."""
        return _row_name(row, self.lines)

    def columns(self) -> dict[str, FloatArray]:
        """The columns present, by name, in the file's order."""
        present = {name: getattr(self, name) for name in COLUMNS}
        return {name: values for name, values in present.items() if values is not None}

    @property
    def rows(self) -> int:
        """Number of measurements."""
        return len(self.load_N)

    @property
    def channels(self) -> tuple[str, ...]:
        """The measured channels present (of Fx_N, Tx_Nm, sinkage_m, Fy_N)."""
        return tuple(name for name in CHANNELS if getattr(self, name) is not None)

    def channel(self, name: str) -> FloatArray:
        """The measured values of channel ``name``; KeyError if it was not measured."""
        values = getattr(self, name) if name in CHANNELS else None
        if values is None:
            raise KeyError(f"{self.source}: no column {name}")
        return values

    @property
    def slip_angle_rad(self) -> FloatArray:
        """β [rad] of every row (0 where the data give no slip angle)."""
        if self.slip_angle_deg is None:
            return np.zeros(self.rows)
        return np.radians(self.slip_angle_deg)

    def subset(self, rows: ArrayLike) -> TestBedData:
        """The measurements of ``rows`` (a boolean mask or indices)."""
        index = np.arange(self.rows)[np.asarray(rows)]
        lines = None if self.lines is None else tuple(self.lines[int(k)] for k in index)
        return replace(self, lines=lines, **{name: values[index] for name, values in self.columns().items()})

    def without(self, *channels: str) -> TestBedData:
        """The same measurements with ``channels`` left out (as if not measured)."""
        unknown = [name for name in channels if name not in CHANNELS]
        if unknown:
            raise ValueError(f"{unknown[0]!r}: expected a measured channel of {', '.join(CHANNELS)}")
        changes: dict[str, Any] = {name: None for name in channels}
        return replace(self, **changes)

    def to_csv(self) -> str:
        """The data as the CSV text :func:`read_testbed_csv` reads (every value to 12 digits)."""
        columns = self.columns()
        lines = [",".join(columns)]
        lines += [",".join(f"{float(v):.12g}" for v in row) for row in zip(*columns.values())]
        return "\n".join(lines) + "\n"


def _header(names: list[str], source: str) -> list[str]:
    """The header's column names, checked: known, none twice, the required ones there."""
    names = [name.strip() for name in names]
    for k, name in enumerate(names):
        if name not in COLUMNS:
            raise ValueError(f"{source}: unknown column {name!r} (column {k + 1} of the header): expected some of "
                             f"{', '.join(COLUMNS)} (the unit is part of the name)")
        if name in names[:k]:
            raise ValueError(f"{source}: column {name} appears twice in the header (columns {names.index(name) + 1} "
                             f"and {k + 1})")
    missing = [name for name in REQUIRED if name not in names]
    if missing:
        raise ValueError(f"{source}: no column {' and '.join(missing)}: every row needs load_N and slip "
                         f"(header: {', '.join(names)})")
    if not any(name in CHANNELS for name in names):
        raise ValueError(f"{source}: no measured column: expected at least one of {', '.join(CHANNELS)} "
                         f"(header: {', '.join(names)})")
    return names


def _number(text: str, row: int, line: int, column: str, source: str) -> float:
    try:
        return float(text)
    except ValueError:
        shown = "empty" if not text.strip() else f"{text.strip()!r} is not a number"
        raise ValueError(f"{source}: row {row + 1} (line {line}), column {column}: {shown}") from None


def _text(path: Path) -> str:
    try:
        return path.read_bytes().decode("utf-8-sig")
    except FileNotFoundError:
        raise ValueError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise ValueError(f"{path}: is a folder: expected a CSV file") from None
    except UnicodeDecodeError as error:
        raise ValueError(f"{path}: not a text file (UTF-8): byte {error.start} cannot be read") from None
    except OSError as error:
        raise ValueError(f"{path}: cannot be read ({error.strerror})") from None


def parse_testbed_csv(text: str, source: str = "data") -> TestBedData:
    """:class:`TestBedData` of CSV ``text`` (see the module docstring); ValueError naming the row,
    line and column of the first bad value, an unknown or repeated column, or a missing one."""
    try:
        records = [(number, row) for number, row in enumerate(csv.reader(io.StringIO(text)), start=1)
                   if row and any(cell.strip() for cell in row) and not row[0].lstrip().startswith("#")]
    except csv.Error as error:  # e.g. a field of more than csv.field_size_limit() characters
        raise ValueError(f"{source}: not a CSV table of numbers ({error})") from None
    if not records:
        raise ValueError(f"{source}: empty: expected a header line (e.g. load_N,slip,Fx_N,Tx_Nm,sinkage_m) and "
                         "one line per measurement")
    names = _header(records[0][1], source)
    lines = [number for number, _ in records[1:]]
    values = np.empty((len(lines), len(names)))
    for k, (line, row) in enumerate(records[1:]):
        if len(row) != len(names):
            raise ValueError(f"{source}: row {k + 1} (line {line}): {len(row)} values, expected {len(names)} (one "
                             "per column of the header)")
        values[k] = [_number(cell, k, line, name, source) for cell, name in zip(row, names)]
    columns = {name: values[:, j] for j, name in enumerate(names)}
    check_values(columns, lines, source)
    return TestBedData(**columns, source=source, lines=tuple(lines))


def read_testbed_csv(path: str | Path) -> TestBedData:
    """The test-bed data of a CSV file (see the module docstring); ValueError with a message
    naming the file and, for a bad value, its row, line and column."""
    path = Path(path)
    return parse_testbed_csv(_text(path), str(path))


@dataclass(frozen=True)
class Prediction:
    """The reference wheel's steady state at the data's inputs: every channel, SI."""

    Fx_N: FloatArray
    Tx_Nm: FloatArray
    sinkage_m: FloatArray
    Fy_N: FloatArray
    #: rows the wheel cannot carry on this soil (sinkage would exceed its radius): channels NaN there
    uncarried: NDArray[np.bool_]

    def channel(self, name: str) -> FloatArray:
        return np.asarray(getattr(self, name))


def predict(soil: Soil, wheel: Wheel, load_N: ArrayLike, slip: ArrayLike, slip_angle_deg: ArrayLike = 0.0,
            rtol: float = 1e-12) -> Prediction:
    """The reference wheel (terramechanics.wheel_state) at each (load, slip, slip angle): Fx, Tx,
    sinkage and Fy. Rows whose load the wheel cannot carry on ``soil`` (a soil too soft for it:
    the sinkage would exceed the radius) are NaN and marked ``uncarried``, instead of an error
    for the whole batch (an optimizer tries such soils on its way)."""
    load, kappa, beta_deg = np.broadcast_arrays(*(np.asarray(a, dtype=float).ravel()
                                                  for a in (load_N, slip, slip_angle_deg)))
    beta = np.radians(beta_deg)
    try:
        state = wheel_state(load, kappa, wheel, soil, rtol=rtol, slip_angle=beta)
        return Prediction(state.Fx, state.Tx, state.sinkage, state.Fy, np.zeros(load.shape, dtype=bool))
    except (ValueError, RuntimeError):
        pass
    carried = _carried(load, kappa, beta, wheel, soil)
    out = [np.full(load.shape, np.nan) for _ in range(4)]
    if carried.any():
        try:
            state = wheel_state(load[carried], kappa[carried], wheel, soil, rtol=rtol, slip_angle=beta[carried])
        except (ValueError, RuntimeError):
            carried[:] = False
        else:
            for target, value in zip(out, (state.Fx, state.Tx, state.sinkage, state.Fy)):
                target[carried] = value
    return Prediction(out[0], out[1], out[2], out[3], ~carried)


def _carried(load: FloatArray, slip: FloatArray, beta: FloatArray, wheel: Wheel, soil: Soil) -> NDArray[np.bool_]:
    """Rows whose load is at most what the wheel carries sunk to its radius (minus a margin)."""
    from rover_cosim.terramechanics import contact_forces

    capacity = contact_forces(np.full(load.shape, wheel.r * 0.999), slip, wheel, soil, slip_angle=beta).Fz
    return load < capacity


def generate_testbed_data(soil: Soil, wheel: Wheel = Wheel(), *, loads: Sequence[float] = (150, 300, 450, 600, 750),
                          slips: Sequence[float] = tuple(np.round(np.arange(-0.2, 0.81, 0.1), 10)),
                          slip_angles_deg: Sequence[float] = (0.0,),
                          channels: Sequence[str] | None = None, noise: float = 0.0, seed: int = 0,
                          source: str = "generated") -> TestBedData:
    """Test-bed data of the reference wheel on ``soil``: one row per (load, slip, slip angle) of
    the grid, the ``channels`` measured (default: Fx_N, Tx_Nm, sinkage_m, and Fy_N if a slip
    angle is not 0), each with Gaussian noise of standard deviation ``noise`` times the
    channel's range (max - min of its noise-free values over the grid), drawn from
    numpy's default generator seeded with ``seed``. The inputs are exact. ValueError if the
    wheel cannot carry a load on this soil."""
    if not (isinstance(noise, (int, float)) and math.isfinite(noise) and 0 <= noise <= 1):
        raise ValueError(f"noise={noise!r}: expected a fraction of each channel's range in [0, 1]")
    angles = tuple(float(a) for a in slip_angles_deg)
    if channels is None:
        channels = ("Fx_N", "Tx_Nm", "sinkage_m") + (("Fy_N",) if any(a != 0 for a in angles) else ())
    unknown = [name for name in channels if name not in CHANNELS]
    if unknown or not channels:
        raise ValueError(f"channels {list(channels)}: expected some of {', '.join(CHANNELS)}")
    grid = np.meshgrid(np.asarray(loads, dtype=float), np.asarray(slips, dtype=float), np.asarray(angles),
                       indexing="ij")
    load, slip, beta = (a.ravel() for a in grid)
    check_values({"load_N": load, "slip": slip, "slip_angle_deg": beta}, source=source)
    state = wheel_state(load, slip, wheel, soil, rtol=1e-12, slip_angle=np.radians(beta))
    exact = {"Fx_N": state.Fx, "Tx_Nm": state.Tx, "sinkage_m": state.sinkage, "Fy_N": state.Fy}
    rng = np.random.default_rng(seed)
    measured = {}
    for name in CHANNELS:  # drawn in a fixed order, so a channel's noise does not depend on the others asked
        draw = rng.standard_normal(load.size)
        if name in channels:
            measured[name] = exact[name] + noise * float(np.ptp(exact[name])) * draw
    if "sinkage_m" in measured:
        measured["sinkage_m"] = np.maximum(measured["sinkage_m"], 0.0)  # a sensor reads no negative sinkage
    return TestBedData(load_N=load, slip=slip, slip_angle_deg=beta if any(a != 0 for a in angles) else None,
                       source=source, **measured)


@dataclass(frozen=True)
class ChannelError:
    """How far a model's channel is from the data's: RMS and largest error, in the channel's
    unit and in per cent of the data's range (max - min) of that channel."""

    channel: str
    rms: float
    max: float
    range: float
    rms_percent: float
    max_percent: float


def prediction_error(prediction: Prediction, data: TestBedData) -> dict[str, ChannelError]:
    """The error of ``prediction`` (at the data's inputs) on every channel the data measure.
    Rows the model cannot carry count as an infinite error."""
    errors = {}
    for name in data.channels:
        measured = data.channel(name)
        difference = np.where(prediction.uncarried, np.inf, prediction.channel(name) - measured)
        rms = float(np.sqrt(np.mean(difference**2)))
        largest = float(np.max(np.abs(difference)))
        span = float(np.ptp(measured)) or float(np.max(np.abs(measured))) or 1.0
        errors[name] = ChannelError(name, rms, largest, span, 100 * rms / span, 100 * largest / span)
    return errors
