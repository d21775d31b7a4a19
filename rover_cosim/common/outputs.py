"""Writing results: all-or-nothing file groups and the record of what a run did."""

from __future__ import annotations

import hashlib
import json
import os
import platform
import subprocess
import sys
import tempfile
from collections.abc import Iterator, Mapping, Sequence
from contextlib import ExitStack, contextmanager
from datetime import UTC, datetime
from importlib import metadata
from pathlib import Path

_UMASK = os.umask(0)
os.umask(_UMASK)

PACKAGES = ("rover-cosim", "numpy", "scipy", "pandas", "matplotlib", "fmpy", "casadi", "rumoca")


def write_all(files: Mapping[Path, bytes]) -> None:
    """Write every file or none of them.

    Each payload goes to a temporary file beside its target first; only when all temporaries
    are complete are they renamed into place (a rename within a directory is atomic), so a
    failure leaves no half-written result and no stray temporary. The renames happen under a lock
    of each target folder (a lock file in the temporary folder, named by the folder's digest), so
    two commands writing the same files at once leave one's set or the other's, never a mix.
    """
    staged: list[tuple[Path, Path]] = []
    files = _with_other_renderings(files)
    try:
        for target, payload in files.items():
            target.parent.mkdir(parents=True, exist_ok=True)
            handle, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent)
            staged.append((Path(name), target))
            with os.fdopen(handle, "wb") as stream:
                stream.write(payload)
            os.chmod(name, result_mode())  # mkstemp makes 0600; results are ordinary files
        with _folder_locks(sorted({target.parent for _, target in staged})):
            for temporary, target in staged:
                os.replace(temporary, target)
    finally:
        for temporary, _ in staged:
            temporary.unlink(missing_ok=True)


def _lock_file(target: Path, kind: str) -> Path:
    """The lock file of ``target`` (kind: lock, for the renames; busy, for a whole command), in the
    temporary folder, named by the digest of the target's path."""
    name = hashlib.sha256(str(target.resolve()).encode()).hexdigest()[:24]
    return Path(tempfile.gettempdir()) / f"rover-cosim-{kind}-{name}"


@contextmanager
def _folder_locks(folders: list[Path]) -> Iterator[None]:
    """Exclusive locks (flock) on ``folders`` (taken in order, so two writers cannot deadlock);
    where there is no flock (Windows) or the lock file cannot be opened (another user's), the
    renames go on without it."""
    try:
        import fcntl
    except ImportError:  # not POSIX
        yield
        return
    with ExitStack() as stack:
        for folder in folders:
            try:
                handle = stack.enter_context(open(_lock_file(folder, "lock"), "a"))  # noqa: SIM115 - held open while locked
            except OSError:
                continue
            fcntl.flock(handle, fcntl.LOCK_EX)
            stack.callback(fcntl.flock, handle, fcntl.LOCK_UN)
        yield


def result_mode() -> int:
    """The file mode of every result: 0666 less the process's umask (0644 under the usual 022)."""
    return 0o666 & ~_UMASK


def _with_other_renderings(files: Mapping[Path, bytes]) -> dict[Path, bytes]:
    """``files`` and, beside each figure rendered in other formats too (common.figures), those."""
    expanded: dict[Path, bytes] = {}
    for target, payload in files.items():
        expanded[target] = payload
        for suffix, data in getattr(payload, "others", {}).items():
            expanded[Path(target).with_suffix(suffix)] = data
    return expanded


def _version(package: str) -> str | None:
    try:
        return metadata.version(package)
    except metadata.PackageNotFoundError:
        return None


def _git_commit() -> str | None:
    try:
        result = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True, timeout=10,
                                cwd=Path(__file__).resolve().parent)
    except (OSError, subprocess.SubprocessError):
        return None
    return result.stdout.strip() or None if result.returncode == 0 else None


def file_sha256(path: Path) -> str:
    """SHA-256 of a file's bytes, as hex."""
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for chunk in iter(lambda: stream.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()


def json_bytes(value: object) -> bytes:
    """``value`` as indented JSON text, UTF-8, ending in a newline."""
    return (json.dumps(value, indent=2, default=str) + "\n").encode()


#: The command line of the command under way (rover_cosim.cli.main sets it); None: the process's.
_COMMAND_LINE: list[str] | None = None


def set_command_line(arguments: Sequence[str] | None) -> None:
    """The command line records give (``rover-cosim`` and its arguments), or None for sys.argv."""
    global _COMMAND_LINE
    _COMMAND_LINE = None if arguments is None else list(arguments)


def run_record(command: str, parameters: Mapping[str, object]) -> dict[str, object]:
    """What a run did: command (and the process's whole command line), parameters, versions, git
    commit, machine, time."""
    return {
        "command": command,
        "command_line": list(_COMMAND_LINE) if _COMMAND_LINE is not None else list(sys.argv),
        "parameters": parameters,
        "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
        "git_commit": _git_commit(),
        "python": sys.version.split()[0],
        "platform": platform.platform(),
        "versions": {name: _version(name) for name in PACKAGES},
    }


def summary_repr(kind: str, files: Sequence[Path] | None = None, **facts: object) -> str:
    """A short repr of a job's result: its kind, where its files went, and a few facts (a result
    holds whole tables, which a repr must not print)."""
    parts = []
    if files:
        folders = sorted({str(Path(f).parent) for f in files})
        parts.append(f"{len(files)} files in {', '.join(folders)}")
    parts += [f"{key}={value}" for key, value in facts.items()]
    return f"{kind}({'; '.join(parts)})"


class Busy(RuntimeError):
    """Another command is writing the same results; the message names it and its PID."""


@contextmanager
def writing(target: Path, command: str) -> Iterator[None]:
    """Hold ``target`` (a results folder or file) for ``command`` while it computes and writes:
    a second command on the same target is refused (Busy, naming the first and its PID) instead
    of the two mixing their files. Best effort where there is no flock (Windows)."""
    try:
        import fcntl
    except ImportError:
        yield
        return
    try:
        handle = open(_lock_file(Path(target), "busy"), "a+")  # noqa: SIM115 - held for the whole command
    except OSError:
        yield
        return
    with handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.seek(0)
            holder = handle.read().strip() or "another process"
            raise Busy(f"{target} is being written by {holder}; wait for it to end, or write elsewhere") from None
        handle.seek(0)
        handle.truncate()
        handle.write(f"PID {os.getpid()} ({command})")
        handle.flush()
        try:
            yield
        finally:
            handle.seek(0)
            handle.truncate()
            fcntl.flock(handle, fcntl.LOCK_UN)
