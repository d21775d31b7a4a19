"""``rover-cosim estimate-soil``: the soil of single-wheel test-bed data, and ``rover-cosim
testbed-data``: such data generated from the reference wheel on a known soil.

estimate-soil writes into its output folder, all files or none:

  soil.toml       the estimated soil in the soil library's format: ``--soil DIR/soil.toml`` takes it
                  everywhere (fig3, identify, simulate, run); a note per parameter says whether it
                  was estimated (with its interval) or kept at the prior's value, and why
  estimate.json   the run record (command, the data file and its SHA-256, wheel, prior, the
                  parameters asked, noise scales given, versions) and the estimate: values,
                  intervals, correlation matrix, residuals per channel and row, the parameters
                  kept and why, the identifiability report, wall time
  fit.csv         the data, the fitted wheel's values and the residuals, one row per measurement
  fit.png         each measured channel against slip: data as markers, the estimated soil as lines
  residuals.png   residuals against slip with the ±2σ noise band

testbed-data writes FILE.csv (the columns estimate-soil reads) and FILE.json beside it (the true
soil and wheel, the grid, the noise and its seed), both or neither.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rover_cosim.common.figures import render
from rover_cosim.common.outputs import file_sha256, json_bytes, run_record, summary_repr, write_all
from rover_cosim.identification.soil_estimation import SoilEstimate, estimate_soil, soil_toml
from rover_cosim.identification.testbed_data import (
    CHANNELS,
    TestBedData,
    generate_testbed_data,
    predict,
    read_testbed_csv,
)
from rover_cosim.terramechanics.library import Choice, as_choice, describe

from .soil_figures import fit_figure, residual_figure

FILES = ("soil.toml", "estimate.json", "fit.csv", "fit.png", "residuals.png")
#: The generator's default grid: 5 loads x 11 slips = 55 measurements.
DEFAULT_LOADS = (150.0, 300.0, 450.0, 600.0, 750.0)
DEFAULT_SLIPS = tuple(float(s) for s in np.round(np.arange(-0.2, 0.81, 0.1), 10))
#: Most rows testbed-data writes (a grid beyond it is refused before any work).
MAX_ROWS = 200_000


@dataclass
class SoilEstimationResult:
    """What ``run_estimate_soil`` found and wrote."""

    estimate: SoilEstimate
    files: list[Path]
    record: dict[str, Any]

    def __repr__(self) -> str:
        values = ", ".join(f"{name}={e.value:.4g}" for name, e in self.estimate.parameters.items())
        return summary_repr("SoilEstimationResult", self.files, estimates=f"[{values}]",
                            seconds=f"{self.estimate.seconds:.2f}")


def fit_table(estimate: SoilEstimate) -> str:
    """The data, the model and the residuals per row, as CSV text."""
    columns = dict(estimate.data.columns())
    for name, channel in estimate.residuals.items():
        columns[f"{name.rsplit('_', 1)[0]}_model_{name.rsplit('_', 1)[1]}"] = channel.fitted
        columns[f"{name.rsplit('_', 1)[0]}_residual_{name.rsplit('_', 1)[1]}"] = channel.residuals
    lines = [",".join(columns)]
    lines += [",".join(f"{float(v):.12g}" for v in row) for row in zip(*columns.values())]
    return "\n".join(lines) + "\n"


def run_estimate_soil(data: Path | TestBedData, out_dir: Path, choice: Choice | None = None,
                      parameters: Sequence[str] | None = None, noise: Mapping[str, float] | None = None
                      ) -> SoilEstimationResult:
    """Estimate the soil of ``data`` (a CSV file, or data in hand) on the wheel of ``choice`` from
    its soil as the prior (default: the paper's soil and wheel), and write the files of the module
    docstring into ``out_dir``, all or none. ValueError with a message for data that cannot be
    read or fitted (nothing written then)."""
    choice = as_choice(choice)
    if isinstance(data, TestBedData):
        measurements, digest = data, None
    else:
        measurements, digest = read_testbed_csv(data), file_sha256(Path(data))
    estimate = estimate_soil(measurements, choice.wheel, choice.soil, parameters, noise=noise)
    source = f"{measurements.source} (sha256 {digest})" if digest else measurements.source
    toml = soil_toml(estimate, title=f"Estimated from {measurements.source}",
                     source=f"rover-cosim estimate-soil on {source}, wheel {choice.wheel_name}, prior soil "
                            f"{choice.soil_name}")
    parameters_record = {"data": measurements.source, "data_sha256": digest, "rows": measurements.rows,
                         "columns": list(measurements.columns()), "wheel": describe(choice)["wheel"],
                         "prior": describe(choice)["soil"], "set": list(choice.overrides),
                         "parameters_asked": None if parameters is None else list(parameters),
                         "noise_scales_given": dict(noise or {})}
    record = run_record("rover-cosim estimate-soil", parameters_record)
    record["estimate"] = estimate.to_dict()
    title = (f"Soil estimated from {Path(measurements.source).name} (wheel {choice.wheel_name}, "
             f"prior {choice.soil_name})")
    files = {
        out_dir / "soil.toml": toml.encode(),
        out_dir / "estimate.json": json_bytes(record),
        out_dir / "fit.csv": fit_table(estimate).encode(),
        out_dir / "fit.png": render(fit_figure(estimate, title), 100),
        out_dir / "residuals.png": render(residual_figure(estimate, title), 100),
    }
    write_all(files, folder=out_dir)
    return SoilEstimationResult(estimate, sorted(files), record)


@dataclass
class TestBedDataResult:
    """What ``write_testbed_data`` generated and wrote."""

    __test__ = False  # not a pytest test class, whatever its name

    data: TestBedData
    files: list[Path]
    record: dict[str, Any]

    def __repr__(self) -> str:
        return summary_repr("TestBedDataResult", self.files, rows=self.data.rows, channels=",".join(self.data.channels))


def write_testbed_data(path: Path, choice: Choice | None = None, loads: Sequence[float] = DEFAULT_LOADS,
                       slips: Sequence[float] = DEFAULT_SLIPS, slip_angles_deg: Sequence[float] = (0.0,),
                       channels: Sequence[str] | None = None, noise: float = 0.0, seed: int = 0) -> TestBedDataResult:
    """Generate test-bed data on the soil and wheel of ``choice`` (identification.testbed_data.
    generate_testbed_data: the grid of loads x slips x slip angles, noise as a fraction of each
    channel's range, seeded) and write ``path`` (CSV) and its record beside it (.json), both or
    neither. ValueError with a message for a grid or noise that cannot be generated."""
    choice = as_choice(choice)
    rows = len(loads) * len(slips) * len(slip_angles_deg)
    if rows > MAX_ROWS:
        raise ValueError(f"{len(loads)} loads x {len(slips)} slips x {len(slip_angles_deg)} slip angles = {rows:,} "
                         f"rows: more than the {MAX_ROWS:,} testbed-data writes")
    data = generate_testbed_data(choice.soil, choice.wheel, loads=loads, slips=slips, slip_angles_deg=slip_angles_deg,
                                 channels=channels, noise=noise, seed=seed, source=str(path))
    text = data.to_csv()
    beta = 0.0 if data.slip_angle_deg is None else data.slip_angle_deg
    exact = predict(choice.soil, choice.wheel, data.load_N, data.slip, beta)
    parameters = {"loads_N": list(map(float, loads)), "slips": list(map(float, slips)),
                  "slip_angles_deg": list(map(float, slip_angles_deg)), "channels": list(data.channels),
                  "noise_fraction_of_range": noise, "seed": seed,
                  "noise_sd": {name: noise * float(np.ptp(exact.channel(name))) for name in data.channels},
                  "truth": describe(choice), "soil": asdict(choice.soil), "wheel": asdict(choice.wheel),
                  "phi_deg": math.degrees(choice.soil.phi)}
    record = run_record("rover-cosim testbed-data", parameters)
    record["csv_sha256"] = hashlib.sha256(text.encode()).hexdigest()
    files = {path: text.encode(), path.with_suffix(".json"): json_bytes(record)}
    write_all(files)
    return TestBedDataResult(data, list(files), record)


__all__ = ["CHANNELS", "FILES", "SoilEstimationResult", "TestBedDataResult", "fit_table", "run_estimate_soil",
           "write_testbed_data"]
