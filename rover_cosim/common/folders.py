"""A results folder replaced as one unit: the new files are written into a sibling folder that
also holds (as hard links, so nothing is copied) everything of the old folder they do not replace
(the run cache, another result set of the same command), and the two folders are then exchanged
by one system call (Linux renameat2 RENAME_EXCHANGE). At every moment the folder's path names
either the old folder or the new one, whole: a process killed before the exchange leaves the old
results, one killed after it the new ones, and the sibling it leaves behind (``.<name>.rover-
cosim-swap-<pid>-*``) is removed by the next writer once that process is gone.

Where the exchange is not available (another system, a file system without it) or the folder is
shared (it holds other folders than the ones named ``keep``: ``results/`` itself, a project
checkout), :func:`exchange_folder` says so and the caller renames file by file instead.
"""

from __future__ import annotations

import errno
import fnmatch
import os
import shutil
import stat
import tempfile
from collections.abc import Callable, Collection
from pathlib import Path

from .scratch import folder_mode, remove_stale_folders, scratch_prefix

#: Folders inside a results folder that are carried over into its replacement (the run caches).
KEEP = ("cache",)
#: At most this many entries are linked into a replacement (more: renamed file by file).
MAX_ENTRIES = 200_000
_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _renameat2() -> Callable[..., int] | None:
    """libc's renameat2 (glibc >= 2.28), or None."""
    try:
        import ctypes

        function = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        return None
    return function


def exchange(first: Path, second: Path) -> bool:
    """Swap the two paths atomically; False where the system or file system cannot (nothing
    changed then), OSError for any other failure."""
    function = _renameat2()
    if function is None:
        return False
    import ctypes

    if function(_AT_FDCWD, os.fsencode(first), _AT_FDCWD, os.fsencode(second), _RENAME_EXCHANGE) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP, errno.EXDEV, errno.EBUSY, errno.EPERM, errno.EACCES):
        return False  # not here: no such call or file system support, a mount point, a sticky folder
    raise OSError(code, os.strerror(code), str(first), None, str(second))


def swappable(folder: Path, keep: Collection[str] = KEEP) -> bool:
    """Whether ``folder`` may be replaced as a whole: absent, or holding files and the ``keep``
    folders only (a folder holding other folders is shared with other commands or the user)."""
    if not folder.exists():
        return True
    if not folder.is_dir() or folder.is_symlink():
        return False
    return all(entry.name in keep or not entry.is_dir() or entry.is_symlink() for entry in folder.iterdir())


def exchange_folder(folder: Path, write: Callable[[Path], Collection[Path]], stale: Collection[str] = (),
                    keep: Collection[str] = KEEP) -> bool:
    """Replace ``folder`` by a sibling into which ``write(staging)`` writes the new files (it
    returns their paths relative to ``staging``), the rest of the old folder carried over but for
    the files matching a pattern of ``stale`` (files of this result set it did not write this
    time). False (nothing changed) where the folder is shared or the exchange is not available;
    OSError if writing fails (the old folder is then untouched). The caller holds the folder's
    lock (outputs.write_all)."""
    folder = Path(folder)
    if not swappable(folder, keep):
        return False
    folder.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_folders(folder.parent, prefix=f".{folder.name}.")
    try:
        staging = Path(tempfile.mkdtemp(prefix=f".{folder.name}.{scratch_prefix('swap')}", dir=folder.parent))
    except PermissionError:  # the folder's parent is not ours to write: the folder itself may be
        return False
    try:
        written = {Path(p) for p in write(staging)}
        if not folder.exists():
            os.chmod(staging, folder_mode())
            os.rename(staging, folder)  # nothing to exchange with; fails if a folder appeared meanwhile
            return True
        os.chmod(staging, stat.S_IMODE(folder.stat().st_mode))
        if not _mirror(folder, staging, written, stale, keep):
            return False
        return exchange(folder, staging)
    finally:
        shutil.rmtree(staging, ignore_errors=True)  # after an exchange: the old folder


def _mirror(folder: Path, staging: Path, written: Collection[Path], stale: Collection[str],
            keep: Collection[str]) -> bool:
    """Hard links in ``staging`` to every file of ``folder`` that is not among ``written``
    (relative paths) nor ``stale``, folders recreated; False if the folder is shared, too large
    or the file system has no hard links."""
    count = 0
    for root, folders, files in os.walk(folder):
        relative = Path(root).relative_to(folder)
        if relative == Path(".") and any(name not in keep and not os.path.islink(os.path.join(root, name))
                                         for name in folders):
            return False  # changed since swappable() looked
        for name in folders:
            _carry(Path(root) / name, staging / relative / name)
        count += len(files)
        if count > MAX_ENTRIES:
            return False
        for name in files:
            if relative / name in written or name.endswith(".part") or _matches(relative / name, stale):
                continue
            try:
                _carry(Path(root) / name, staging / relative / name)
            except OSError as error:
                if error.errno in (errno.EPERM, errno.EXDEV, errno.EMLINK, errno.ENOTSUP, errno.EOPNOTSUPP):
                    return False
                raise
    return True


def _carry(source: Path, copy: Path) -> None:
    """``source`` at ``copy``: a folder made anew (same mode), a symbolic link copied, a file
    hard-linked."""
    if source.is_symlink():
        os.symlink(os.readlink(source), copy)
    elif source.is_dir():
        copy.mkdir(mode=stat.S_IMODE(source.stat().st_mode), exist_ok=True)
    else:
        os.link(source, copy, follow_symlinks=False)


def _matches(path: Path, patterns: Collection[str]) -> bool:
    return any(fnmatch.fnmatchcase(path.as_posix(), pattern) for pattern in patterns)
