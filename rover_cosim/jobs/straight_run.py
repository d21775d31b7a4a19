"""The paper's straight run's time grid (Sec. 4: 20 s in 1 ms steps, rows kept every 10 ms) and the
check of the options a run takes: a module of their own, with nothing heavy to import, so that the
command line refuses a bad option before it imports the job (pandas, scipy, matplotlib: seconds)."""

from __future__ import annotations

from rover_cosim.common.rows import steps_between_rows
from rover_cosim.control.calibration import Calibration

STOP_TIME = 20.0  # s
STEP = 1e-3       # s
#: s, the rows the trajectory files keep by default (the runs step at STEP; metrics use every step)
RECORD_INTERVAL = 1e-2


def check_options(record_interval: float, adapt: Calibration | None = None) -> None:
    """ValueError naming what of the options the runs cannot take: a record interval that is not a
    whole number of steps, a calibration that does not end before the run."""
    steps_between_rows(record_interval, STEP)
    if adapt is not None and not adapt.duration < STOP_TIME:
        raise ValueError(f"calibration {adapt.duration!r} s: expected a length in (0, {STOP_TIME:g}) s, shorter than "
                         f"the {STOP_TIME:g} s run")
