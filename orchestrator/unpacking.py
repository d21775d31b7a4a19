"""Where a run's FMUs are unpacked: one temporary folder per run,
``<tmp>/rover-cosim-run-<pid>-<random>``, removed when the run ends whatever happened; folders
left by processes that were killed (SIGKILL, where no clean-up runs) are removed by the next run
(``common.scratch``).

Instances of one FMU file share one unpacked copy, and so the library loaded from it (six wheels
of one Wheel.fmu: one copy, one library), as FMI allows unless the FMU says
``canBeInstantiatedOnlyOncePerProcess``: such an FMU gets a copy per instance, each loaded as a
library of its own.
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import fmpy

from rover_cosim.common.scratch import PREFIX, remove_stale_folders, scratch_prefix

from .model import FmuEntry

#: The temporary folder of a run's unpacked FMUs: ``<tmp>/rover-cosim-run-<pid>-<random>``.
UNZIP_PREFIX = f"{PREFIX}run-"


@contextmanager
def run_folder() -> Iterator[Path]:
    """A new temporary folder for this run's FMUs (stale ones removed first), removed on leaving."""
    remove_stale_folders()
    with tempfile.TemporaryDirectory(prefix=scratch_prefix("run")) as folder:
        yield Path(folder)


def unpack(entry: FmuEntry, root: Path, shared: dict[Path, Path] | None = None) -> Path:
    """The folder under ``root`` holding ``entry``'s FMU unpacked: ``shared`` (file -> folder, kept
    by the caller for one run) gives the copy an earlier instance of the same file made, unless
    the FMU can be instantiated only once per process."""
    once = bool(getattr(entry.capabilities, "canBeInstantiatedOnlyOncePerProcess", False))
    key = Path(entry.path).resolve()
    if shared is not None and not once and key in shared:
        return shared[key]
    folder = root / entry.name
    fmpy.extract(str(entry.path), str(folder))
    if shared is not None and not once:
        shared[key] = folder
    return folder


__all__ = ["UNZIP_PREFIX", "remove_stale_folders", "run_folder", "unpack"]
