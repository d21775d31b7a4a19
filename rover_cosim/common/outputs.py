"""Writing results: all-or-nothing file groups and the record of what a run did."""

from __future__ import annotations

import functools
import hashlib
import json
import os
import platform
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
from collections.abc import Collection, Iterator, Mapping, Sequence
from contextlib import contextmanager
from datetime import UTC, datetime
from importlib import metadata
from pathlib import Path

from .folders import exchange_folder
from .locks import Busy as Busy  # noqa: F401 - re-exported: the CLI takes them from here
from .locks import folder_locks
from .locks import writing as writing  # noqa: F401
from .scratch import UMASK

PACKAGES = ("rover-cosim", "numpy", "scipy", "pandas", "matplotlib", "fmpy", "casadi", "rumoca")


class OutputError(Exception):
    """The results were computed but could not be written where asked; the message says why and
    where they were saved instead."""


def write_all(files: Mapping[Path, bytes], folder: Path | None = None, stale: Collection[str] = (),
              complete: bool = True) -> None:
    """Write every file or none of them.

    ``folder`` given (a results folder of one command, holding every file of ``files``): the
    folder is replaced as one unit (common.folders: a sibling with the new files and the rest of
    the old folder, hard-linked, then one exchange), the files of ``stale`` (patterns relative to
    the folder: this result set's files it did not write this time) left out. Otherwise, or where
    the folder is shared or the system cannot exchange folders: each payload goes to a temporary
    file beside its target, and only when all are complete are they renamed into place (each
    rename is atomic), under a lock of each target folder (a lock file in the temporary folder,
    named by the folder's digest), so two commands writing the same files at once leave one's set
    or the other's, never a mix; SIGINT and SIGTERM wait until the renames are done.

    A failure leaves the previous results and no stray temporary, and raises OutputError naming
    a folder (in the temporary folder, else the home folder) where the new files were saved.
    ``complete``: the files are a command's result set (counted by :func:`committed`), not what
    is kept of a failed run.
    """
    files = with_provenance(with_units(_with_other_renderings(files)))
    try:
        if folder is None or not _exchange(Path(folder), files, stale, complete):
            _rename_each(files, complete)
    except OSError as error:
        raise OutputError(_saved(files, folder, error)) from None


def committed() -> int:
    """How many result sets this process has written (write_all calls of complete results)."""
    return _COMMITTED


_COMMITTED = 0


@contextmanager
def _signals_held() -> Iterator[None]:
    """SIGINT and SIGTERM held back while the last step of a write is done and counted, so that
    they cannot cut it short: their handlers (Python's, run in the main thread) are replaced by
    one that notes them, and the notes are handed to the previous handlers afterwards. (Blocking
    them with pthread_sigmask would not do: the kernel gives them to another thread, e.g. BLAS's.)"""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    previous = {number: signal.signal(number, lambda caught_number, frame: caught.append(caught_number))
                for number in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for held, handler in previous.items():
            signal.signal(held, handler)
        for number in caught:
            handler = previous[signal.Signals(number)]
            if callable(handler):
                handler(number, None)  # KeyboardInterrupt, as the command's handlers raise it
            elif handler == signal.SIG_DFL:
                os.kill(os.getpid(), number)


def _exchange(folder: Path, files: Mapping[Path, bytes], stale: Collection[str], complete: bool) -> bool:
    """``files`` written by replacing ``folder`` as one unit; False where it cannot be."""
    global _COMMITTED
    relative = {target: Path(target).relative_to(folder) for target in files}

    def write(staging: Path) -> list[Path]:
        for target, payload in files.items():
            path = staging / relative[target]
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(payload)
            os.chmod(path, result_mode())
        return list(relative.values())

    if any(".." in path.parts or path.is_absolute() for path in relative.values()):
        return False
    with folder_locks([folder]), _signals_held():
        done = exchange_folder(folder, write, stale)
        _COMMITTED += done and complete
    return done


def staging_file(target: Path) -> tuple[int, Path]:
    """A new temporary file beside ``target`` (an open descriptor and its path), where a result
    is written before it is renamed into place (:func:`publish`)."""
    target.parent.mkdir(parents=True, exist_ok=True)
    handle, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent)
    return handle, Path(name)


def _rename_each(files: Mapping[Path, bytes], complete: bool, written: Mapping[Path, Path] | None = None) -> None:
    """Temporaries beside the targets (``written``: target -> a temporary already written), all
    renamed into place under the folders' locks, or none."""
    global _COMMITTED
    given: list[tuple[Path, Path]] = [(temporary, target) for target, temporary in (written or {}).items()]
    made: list[tuple[Path, Path]] = []
    try:
        for target, payload in files.items():
            handle, name = staging_file(target)
            made.append((name, target))
            with os.fdopen(handle, "wb") as stream:
                stream.write(payload)
        staged = given + made
        for temporary, _ in staged:
            os.chmod(temporary, result_mode())  # mkstemp makes 0600; results are ordinary files
        with folder_locks(sorted({target.parent for _, target in staged})), _signals_held():
            for temporary, target in staged:
                os.replace(temporary, target)
            _COMMITTED += complete
    finally:
        for temporary, _ in made:  # the caller's own (``written``) are the caller's to remove
            temporary.unlink(missing_ok=True)


def publish(written: Mapping[Path, Path], files: Mapping[Path, bytes], complete: bool = True) -> None:
    """Like :func:`write_all` without a folder, for results of which some were written as they
    were computed: ``written`` maps targets to temporaries from :func:`staging_file` (removed
    whatever happens), ``files`` holds the rest as bytes. A failure saves every file elsewhere and
    raises OutputError saying where."""
    try:
        _rename_each(files, complete, written)
    except OSError as error:
        everything = dict(files)
        for target, temporary in written.items():
            try:
                everything[target] = temporary.read_bytes()
            except OSError:
                pass
            temporary.unlink(missing_ok=True)
        raise OutputError(_saved(everything, None, error)) from None


def _saved(files: Mapping[Path, bytes], folder: Path | None, error: OSError) -> str:
    """Save ``files`` where they can be (a new folder in the temporary folder, else in the home
    folder), with their paths below their common folder; the message of the failure."""
    root = Path(folder) if folder is not None else Path(os.path.commonpath([Path(t).parent for t in files]))
    reason = f"{error.strerror or error}" + (f": {error.filename}" if error.filename else "")
    for place in (Path(tempfile.gettempdir()), Path.home()):
        try:
            kept = Path(tempfile.mkdtemp(prefix=f"rover-cosim-saved.{root.name or 'results'}.", dir=place))
            for target, payload in files.items():
                path = kept / Path(target).relative_to(root)
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_bytes(payload)
        except OSError:
            continue
        return (f"the results could not be written to {root} ({reason}); they are saved in {kept}: move them where "
                "they belong")
    return f"the results could not be written to {root} ({reason}), nor saved elsewhere; they are lost"


def output_problem(path: Path, folder: bool, need_bytes: float = 0) -> str | None:
    """Why results cannot go to ``path`` (a folder to write into, or a file to write when
    ``folder`` is False), or None: a file where a folder is expected or the other way round, a
    file above it, a folder that cannot be written (a file is made and removed there to know), or
    less free space than ``need_bytes`` (an estimate) on its file system."""
    path = Path(path)
    if folder and path.exists() and not path.is_dir():
        return "is a file: expected a folder (absent or existing)"
    if not folder and path.is_dir():
        return "is a folder: expected a file name"
    existing = path if folder else path.parent
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if not existing.is_dir():
        return f"{existing} is a file, not a folder"
    try:
        handle, probe = tempfile.mkstemp(prefix=".rover-cosim-probe.", dir=existing)
    except OSError as error:
        return f"the folder {existing} cannot be written ({error.strerror})"
    os.close(handle)
    os.unlink(probe)
    free = shutil.disk_usage(existing).free
    if free < need_bytes:
        return (f"{free / 1e6:.1f} MB free on the file system of {existing}; the results need about "
                f"{need_bytes / 1e6:.1f} MB")
    return None


def result_mode() -> int:
    """The file mode of every result: 0666 less the process's umask (0644 under the usual 022)."""
    return 0o666 & ~UMASK


def _with_other_renderings(files: Mapping[Path, bytes]) -> dict[Path, bytes]:
    """``files`` and, beside each figure rendered in other formats too (common.figures), those."""
    expanded: dict[Path, bytes] = {}
    for target, payload in files.items():
        expanded[target] = payload
        for suffix, data in getattr(payload, "others", {}).items():
            expanded[Path(target).with_suffix(suffix)] = data
    return expanded


def with_units(files: Mapping[Path, bytes]) -> dict[Path, bytes]:
    """``files`` with the record written beside CSV tables (the JSON of the same name, else the one
    JSON written into the same folder) saying each table's column units: ``"units": {"table.csv":
    {"Fz_1": "N", ...}}`` (``common.units.column_unit``); the tables' bytes are not touched, so
    their headers stay the plain names pandas users index by."""
    from .units import column_units

    out = dict(files)
    units: dict[Path, dict[str, dict[str, str]]] = {}
    jsons = [Path(t) for t in files if Path(t).suffix == ".json"]
    for target, payload in files.items():
        target = Path(target)
        if target.suffix != ".csv":
            continue
        same = target.with_suffix(".json")
        beside = [j for j in jsons if j.parent == target.parent]
        record = same if same in jsons else (beside[0] if len(beside) == 1 else None)
        if record is None:
            continue
        import csv
        import io

        header = next(csv.reader(io.StringIO(bytes(payload[:65536]).decode(errors="replace").split("\n", 1)[0])), [])
        found = column_units(header)
        if found:
            units.setdefault(record, {})[target.name] = found
    for record, tables in units.items():
        try:
            data = json.loads(files[record])
        except ValueError:
            continue
        if isinstance(data, dict) and "units" not in data:
            out[record] = json_bytes({**data, "units": tables})
    return out


#: The PNG text chunk that names the record a figure was written with.
PNG_RECORD_KEY = "rover-cosim record"
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def with_provenance(files: Mapping[Path, bytes]) -> dict[Path, bytes]:
    """``files`` with every PNG among them carrying the record written with it: a text chunk
    ``rover-cosim record`` = "<record's file name> sha256:<its digest>" (the record: the JSON
    of the same name, else the one JSON written into the same folder), so that a figure found
    alone says what produced it. A PNG without such a record is left as it is."""
    records = {target: payload for target, payload in files.items() if Path(target).suffix == ".json"}
    out: dict[Path, bytes] = {}
    for target, payload in files.items():
        target = Path(target)
        record = None
        if target.suffix == ".png" and bytes(payload[:8]) == _PNG_SIGNATURE:
            same = target.with_suffix(".json")
            beside = [r for r in records if Path(r).parent == target.parent]
            record = same if same in records else (beside[0] if len(beside) == 1 else None)
        if record is None:
            out[target] = payload
            continue
        text = f"{Path(record).name} sha256:{hashlib.sha256(records[record]).hexdigest()}"
        out[target] = png_with_text(bytes(payload), PNG_RECORD_KEY, text)
    return out


def png_with_text(png: bytes, key: str, text: str) -> bytes:
    """``png`` with a tEXt chunk ``key`` = ``text`` after its header chunk (Latin-1 text)."""
    import struct
    import zlib

    data = key.encode("latin-1") + b"\0" + text.encode("latin-1", errors="replace")
    chunk = struct.pack(">I", len(data)) + b"tEXt" + data + struct.pack(">I", zlib.crc32(b"tEXt" + data))
    header_end = 8 + 4 + 4 + 13 + 4  # signature, then IHDR: length, type, 13 bytes, CRC
    return png[:header_end] + chunk + png[header_end:]


def png_text(png: bytes) -> dict[str, str]:
    """The tEXt chunks of ``png`` (key -> text)."""
    import struct

    found, at = {}, 8
    while at + 8 <= len(png):
        (length,), kind = struct.unpack(">I", png[at:at + 4]), png[at + 4:at + 8]
        if kind == b"tEXt":
            key, _, value = png[at + 8:at + 8 + length].partition(b"\0")
            found[key.decode("latin-1")] = value.decode("latin-1")
        at += 12 + length
    return found


def _version(package: str) -> str | None:
    try:
        return metadata.version(package)
    except metadata.PackageNotFoundError:
        return None


def _git(*arguments: str) -> bytes | None:
    """git's output run in the tool's own source tree, None where there is no git or no tree."""
    try:
        result = subprocess.run(["git", *arguments], capture_output=True, timeout=10,
                                cwd=Path(__file__).resolve().parent)
    except (OSError, subprocess.SubprocessError):
        return None
    return result.stdout if result.returncode == 0 else None


def _working_directory() -> str | None:
    """The process's working directory (None where it was removed meanwhile)."""
    try:
        return os.getcwd()
    except OSError:
        return None


@functools.lru_cache(maxsize=1)
def source_tree() -> dict[str, object]:
    """The tool's source tree (once per process): its git commit, whether it had uncommitted
    changes (``git_dirty``) and, when it had, the SHA-256 of ``git diff HEAD`` (``git_diff_sha256``:
    two runs with the same digest ran the same code). None values where it is not a git checkout."""
    commit = _git("rev-parse", "HEAD")
    if commit is None:
        return {"git_commit": None, "git_dirty": None}
    status = _git("status", "--porcelain", "--untracked-files=no")
    dirty = bool(status.strip()) if status is not None else None
    tree: dict[str, object] = {"git_commit": commit.decode().strip() or None, "git_dirty": dirty}
    if dirty:
        diff = _git("diff", "HEAD")
        tree["git_diff_sha256"] = hashlib.sha256(diff).hexdigest() if diff is not None else None
    return tree


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
    """What a run did: command (and the process's whole command line), parameters, versions, the
    working directory, git commit (and whether the tree had uncommitted changes, with the diff's
    digest), machine, time."""
    return {
        "command": command,
        "command_line": list(_COMMAND_LINE) if _COMMAND_LINE is not None else list(sys.argv),
        "parameters": parameters,
        "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
        "working_directory": _working_directory(),
        **source_tree(),
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
