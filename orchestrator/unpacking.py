"""Where a run's FMUs are unpacked: one temporary folder per run,
``<tmp>/rover-cosim-run-<pid>-<random>``, removed when the run ends whatever happened; folders
left by processes that were killed (SIGKILL, where no clean-up runs) are removed by the next run
(``common.scratch``).
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from rover_cosim.common.scratch import PREFIX, remove_stale_folders, scratch_prefix

#: The temporary folder of a run's unpacked FMUs: ``<tmp>/rover-cosim-run-<pid>-<random>``.
UNZIP_PREFIX = f"{PREFIX}run-"


@contextmanager
def run_folder() -> Iterator[Path]:
    """A new temporary folder for this run's FMUs (stale ones removed first), removed on leaving."""
    remove_stale_folders()
    with tempfile.TemporaryDirectory(prefix=scratch_prefix("run")) as folder:
        yield Path(folder)


__all__ = ["UNZIP_PREFIX", "remove_stale_folders", "run_folder"]
