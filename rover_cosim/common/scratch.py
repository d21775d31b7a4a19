"""Temporary folders of a process, named so that another process can tell when they are left
over: ``<tmp>/rover-cosim-<kind>-<pid>-<random>`` (kind: run, ssp, testbed). Each is removed by
its owner when it is done; the ones of processes that are gone (killed with SIGKILL, or pool
workers, which exit without running clean-ups) are removed by the next command, and by a pool's
parent once its workers have ended."""

from __future__ import annotations

import glob
import os
import re
import shutil
import tempfile
from pathlib import Path

#: The start of every such folder's name.
PREFIX = "rover-cosim-"
_NAME = re.compile(rf"{PREFIX}([a-z]+)-(\d+)-")
#: The process's umask (read once: reading it means setting it).
UMASK = os.umask(0)
os.umask(UMASK)


def cache_folder() -> Path:
    """The user's cache folder of rover-cosim (kept between commands: compiled native code, build
    times): ``$ROVER_COSIM_CACHE``, else ``$XDG_CACHE_HOME/rover-cosim`` or ``~/.cache/rover-cosim``."""
    configured = os.environ.get("ROVER_COSIM_CACHE")
    if configured:
        return Path(configured)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "rover-cosim"


def folder_mode() -> int:
    """The mode of a folder of results: 0777 less the process's umask."""
    return 0o777 & ~UMASK


def scratch_prefix(kind: str) -> str:
    """The ``prefix`` of tempfile's folders of ``kind`` for this process."""
    return f"{PREFIX}{kind}-{os.getpid()}-"


def remove_stale_folders(where: Path | None = None, prefix: str = "") -> list[Path]:
    """Remove the temporary folders of processes that are gone (in the temporary folder, or in
    ``where`` those whose names start with ``prefix`` and then ours); returns what was removed."""
    removed = []
    for folder in Path(where or tempfile.gettempdir()).glob(f"{glob.escape(prefix)}{PREFIX}*-*-*"):
        found = _NAME.match(folder.name[len(prefix):])
        if found is None or int(found.group(2)) == os.getpid() or _alive(int(found.group(2))):
            continue
        shutil.rmtree(folder, ignore_errors=True)
        removed.append(folder)
    return removed


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs (POSIX: signal 0; elsewhere always taken as alive, since
    os.kill would end the process there)."""
    if os.name != "posix":
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True
