"""Where runs' FMUs are unpacked: one temporary folder per process,
``<tmp>/rover-cosim-run-<pid>-<random>``, made at the first run and removed when the process
exits; folders left by processes that were killed (SIGKILL, where no clean-up runs) are removed
by the next command (``common.scratch``).

An FMU file is unpacked once per process, by its path, size and modification time: the runs of a
Monte Carlo worker or of a script reuse the copy (an FMU file that changes is unpacked again).
Instances of one FMU file share that copy, and so the library loaded from it (six wheels of one
Wheel.fmu: one copy, one library), as FMI allows unless the FMU says
``canBeInstantiatedOnlyOncePerProcess``: such an FMU gets a copy per instance in a folder of the
run (``run_folder``), each loaded as a library of its own.
"""

from __future__ import annotations

import atexit
import shutil
import tempfile
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from rover_cosim.common.scratch import PREFIX, remove_stale_folders, scratch_prefix

from .archives import release, unpack_archive
from .model import FmuEntry

#: The temporary folder of a process's unpacked FMUs: ``<tmp>/rover-cosim-run-<pid>-<random>``.
UNZIP_PREFIX = f"{PREFIX}run-"


class _ProcessCopies:
    """This process's unpacked FMU files, by (path, size, modification time)."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.root: Path | None = None
        self.folders: dict[tuple[str, int, int], Path] = {}

    def folder(self, path: Path) -> Path:
        stat = path.stat()
        key = (str(path.resolve()), stat.st_size, stat.st_mtime_ns)
        with self.lock:
            found = self.folders.get(key)
            if found is not None and (found / "modelDescription.xml").is_file():
                return found
            target = Path(tempfile.mkdtemp(prefix="fmu-", dir=self._root()))
            unpack_archive(path, target)
            self.folders[key] = target
            return target

    def _root(self) -> Path:
        if self.root is None or not self.root.is_dir():
            remove_stale_folders()
            self.root = Path(tempfile.mkdtemp(prefix=scratch_prefix("run")))
            self.folders.clear()
            atexit.register(shutil.rmtree, self.root, True)
        return self.root


_COPIES = _ProcessCopies()
#: The bytes unpacked into each run folder (given back to the unpacking budget when it is removed).
_RUN_BYTES: dict[Path, int] = {}


@contextmanager
def run_folder() -> Iterator[Path]:
    """A new temporary folder for one run's own copies (FMUs instantiated once per process),
    removed on leaving."""
    remove_stale_folders()
    with tempfile.TemporaryDirectory(prefix=scratch_prefix("run")) as folder:
        try:
            yield Path(folder)
        finally:
            release(_RUN_BYTES.pop(Path(folder), 0))


def once_per_process(entry: FmuEntry) -> bool:
    """Whether ``entry``'s FMU says it can be instantiated only once per process."""
    return bool(getattr(entry.capabilities, "canBeInstantiatedOnlyOncePerProcess", False))


def unpack(entry: FmuEntry, root: Path | None = None) -> Path:
    """The folder holding ``entry``'s FMU unpacked: the process's copy of its file, or, for an FMU
    that can be instantiated only once per process, a copy of its own under ``root`` (a
    ``run_folder``). ``archives.UnpackError`` for an archive that may not be unpacked (an entry
    outside its folder, a link, more than the process's unpacking limit, a full disk)."""
    if once_per_process(entry):
        if root is None:
            raise ValueError(f"{entry.name}: {Path(entry.path).name} can be instantiated only once per process: "
                             "expected a run folder for its own copy")
        folder = root / entry.name
        _RUN_BYTES[root] = _RUN_BYTES.get(root, 0) + unpack_archive(Path(entry.path), folder)
        return folder
    return _COPIES.folder(Path(entry.path))


__all__ = ["UNZIP_PREFIX", "once_per_process", "remove_stale_folders", "run_folder", "unpack"]
