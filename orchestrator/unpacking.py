"""Where a run's FMUs are unpacked: one temporary folder per run,
``<tmp>/rover-cosim-run-<pid>-<random>``, removed when the run ends whatever happened; folders
left by runs whose process was killed (SIGKILL, where no clean-up runs) are removed by the next run.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

#: The temporary folder of a run's unpacked FMUs: ``<tmp>/rover-cosim-run-<pid>-<random>``.
UNZIP_PREFIX = "rover-cosim-run-"


def remove_stale_folders() -> list[Path]:
    """Remove the unpacked FMUs of runs whose process is gone; returns what was removed."""
    removed = []
    for folder in Path(tempfile.gettempdir()).glob(f"{UNZIP_PREFIX}*-*"):
        pid = folder.name[len(UNZIP_PREFIX):].split("-", 1)[0]
        if not pid.isdigit() or int(pid) == os.getpid() or _alive(int(pid)):
            continue
        shutil.rmtree(folder, ignore_errors=True)
        removed.append(folder)
    return removed


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


@contextmanager
def run_folder() -> Iterator[Path]:
    """A new temporary folder for this run's FMUs (stale ones removed first), removed on leaving."""
    remove_stale_folders()
    with tempfile.TemporaryDirectory(prefix=f"{UNZIP_PREFIX}{os.getpid()}-") as folder:
        yield Path(folder)
