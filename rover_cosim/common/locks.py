"""Locks of results, by flock on a lock file named by the digest of the results' path: a whole
command holds its output (:func:`writing`: a second command on it is refused, naming the first),
a writer holds a folder while it renames or exchanges its files (:func:`folder_locks`). A lock
file is removed by its holder when it lets go (a process that opened it meanwhile sees that and
takes the new one); one left by a killed process is removed once it is a day old and free.

The lock files live in a folder of the user's own (:func:`lock_folder`: mode 0700 under
$XDG_RUNTIME_DIR, else the user's cache folder, else the temporary folder), checked to be a real
folder that is the user's and nobody else's, and are opened without following a link: no one
else can plant a file or a link there to make a run write into another file. Best effort where
there is no flock (Windows)."""

from __future__ import annotations

import hashlib
import os
import stat
import tempfile
import time
from collections.abc import Iterator
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import IO


class Busy(RuntimeError):
    """Another command is writing the same results; the message names it and its PID."""


class _Held(Exception):
    """The lock is someone else's; ``holder``: what they wrote in it."""

    def __init__(self, holder: str) -> None:
        super().__init__(holder)
        self.holder = holder


#: s, the age after which a lock file no process holds is removed.
STALE_SECONDS = 86_400.0


def lock_folder() -> Path | None:
    """The folder of the lock files: ``rover-cosim-locks`` under $XDG_RUNTIME_DIR, else under the
    user's cache folder ($XDG_CACHE_HOME or ~/.cache), else ``rover-cosim-locks-<uid>`` in the
    temporary folder; made with mode 0700, and taken only where it is a real folder (not a link)
    owned by this user with no access for others. None where there is no such folder (no locks)."""
    uid = os.getuid() if hasattr(os, "getuid") else None
    runtime, cache = os.environ.get("XDG_RUNTIME_DIR"), os.environ.get("XDG_CACHE_HOME")
    candidates = [Path(runtime) / "rover-cosim-locks"] if runtime else []
    candidates.append(Path(cache or Path.home() / ".cache") / "rover-cosim" / "locks")
    candidates.append(Path(tempfile.gettempdir()) / f"rover-cosim-locks-{uid if uid is not None else 'user'}")
    for folder in candidates:
        try:
            folder.parent.mkdir(parents=True, exist_ok=True)
            folder.mkdir(mode=0o700, exist_ok=True)
        except OSError:
            continue
        if _private(folder, uid):
            return folder
    return None


def _private(folder: Path, uid: int | None) -> bool:
    """Whether ``folder`` is a real folder of this user that no one else may enter."""
    try:
        found = os.lstat(folder)
    except OSError:
        return False
    if not stat.S_ISDIR(found.st_mode):
        return False
    if uid is None:  # Windows: the user's own profile folders
        return True
    return found.st_uid == uid and found.st_mode & 0o077 == 0


def lock_file(target: Path, kind: str) -> Path | None:
    """The lock file of ``target`` (kind: lock, for the renames; busy, for a whole command), in
    :func:`lock_folder`, named by the digest of the target's path (any bytes: a path that is not
    UTF-8 too); None where there is no private folder for it."""
    folder = lock_folder()
    if folder is None:
        return None
    name = hashlib.sha256(os.fsencode(Path(target).resolve())).hexdigest()[:24]
    return folder / f"rover-cosim-{kind}-{name}"


def remove_stale_locks(folder: Path | None = None, age: float = STALE_SECONDS) -> list[Path]:
    """Remove the lock files older than ``age`` seconds that no process holds (left by a killed
    one); the ones removed."""
    try:
        import fcntl
    except ImportError:
        return []
    folder = folder or lock_folder()
    removed: list[Path] = []
    if folder is None:
        return removed
    now = time.time()
    for path in folder.glob("rover-cosim-*"):
        try:
            if now - os.lstat(path).st_mtime < age:
                continue
            descriptor = os.open(path, os.O_RDWR | getattr(os, "O_NOFOLLOW", 0))
        except OSError:
            continue
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
            os.unlink(path)
            removed.append(path)
        except OSError:
            pass  # held: not stale
        finally:
            os.close(descriptor)
    return removed


@contextmanager
def _held(path: Path | None, wait: bool) -> Iterator[IO[str] | None]:
    """An exclusive flock on the lock file ``path`` (None where none can be taken), the file
    removed when let go; without ``wait``, _Held if another process holds it. The file is opened
    without following a link and made readable by its owner only."""
    try:
        import fcntl
    except ImportError:  # not POSIX
        yield None
        return
    if path is None:
        yield None
        return
    while True:
        try:
            descriptor = os.open(path, os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0) | os.O_CLOEXEC, 0o600)
        except OSError:
            yield None
            return
        handle = os.fdopen(descriptor, "r+")
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | (0 if wait else fcntl.LOCK_NB))
        except BlockingIOError:
            handle.seek(0)
            holder = handle.read().strip()
            handle.close()
            raise _Held(holder) from None
        except BaseException:
            handle.close()
            raise
        if _same_file(path, handle):
            break
        handle.close()  # its holder removed it while we waited: take the one there now
    try:
        yield handle
    finally:
        try:
            os.unlink(path)
        except OSError:
            pass
        handle.close()  # lets go of the flock


def _same_file(path: Path, handle: IO[str]) -> bool:
    try:
        return os.stat(path).st_ino == os.fstat(handle.fileno()).st_ino
    except FileNotFoundError:
        return False


@contextmanager
def folder_locks(folders: list[Path]) -> Iterator[None]:
    """Exclusive locks on ``folders``, taken in order (so two writers cannot deadlock)."""
    with ExitStack() as stack:
        for folder in folders:
            stack.enter_context(_held(lock_file(folder, "lock"), wait=True))
        yield


@contextmanager
def writing(target: Path, command: str) -> Iterator[None]:
    """Hold ``target`` (a results folder or file) for ``command`` while it computes and writes:
    a second command on the same target is refused (Busy, naming the first and its PID) instead
    of the two mixing their files."""
    remove_stale_locks()
    try:
        with _held(lock_file(Path(target), "busy"), wait=False) as handle:
            if handle is not None:
                handle.seek(0)
                handle.truncate()
                handle.write(f"PID {os.getpid()} ({command})")
                handle.flush()
            yield
    except _Held as held:
        raise Busy(f"{target} is being written by {held.holder or 'another process'}; wait for it to end, or write "
                   "elsewhere") from None
