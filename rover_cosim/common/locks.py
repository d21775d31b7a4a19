"""Locks of results, by flock on a lock file in the temporary folder named by the digest of the
results' path: a whole command holds its output (:func:`writing`: a second command on it is
refused, naming the first), a writer holds a folder while it renames or exchanges its files
(:func:`folder_locks`). A lock file is removed by its holder when it lets go (a process that
opened it meanwhile sees that and takes the new one), so none are left behind. Best effort where
there is no flock (Windows) or the lock file is another user's."""

from __future__ import annotations

import hashlib
import os
import tempfile
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


def lock_file(target: Path, kind: str) -> Path:
    """The lock file of ``target`` (kind: lock, for the renames; busy, for a whole command), in the
    temporary folder, named by the digest of the target's path."""
    name = hashlib.sha256(str(Path(target).resolve()).encode()).hexdigest()[:24]
    return Path(tempfile.gettempdir()) / f"rover-cosim-{kind}-{name}"


@contextmanager
def _held(path: Path, wait: bool) -> Iterator[IO[str] | None]:
    """An exclusive flock on the lock file ``path`` (None where none can be taken), the file
    removed when let go; without ``wait``, _Held if another process holds it."""
    try:
        import fcntl
    except ImportError:  # not POSIX
        yield None
        return
    while True:
        try:
            handle = open(path, "a+")  # noqa: SIM115 - held open while locked
        except OSError:
            yield None
            return
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
