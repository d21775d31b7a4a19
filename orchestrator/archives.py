"""Unpacking zip archives (FMUs, SSP archives) without trusting them: no entry may land outside
the target folder or be a link, and the bytes really written (not the sizes the archive
declares) count against one limit per process, shared by every archive it unpacks, so that an
FMU inside an SSP archive, or many FMUs, cannot together fill the disk (a 6.9 KB archive held
200 MB; a 2 MB FMU 2 GB). The limit: ROVER_COSIM_UNPACK_MAX_BYTES, else :data:`SIZE_LIMIT`.
"""

from __future__ import annotations

import os
import threading
import zipfile
from pathlib import Path

#: The most this process unpacks in all [bytes, uncompressed]; ROVER_COSIM_UNPACK_MAX_BYTES sets another.
SIZE_LIMIT = 4 * 2**30
#: The environment variable that sets the limit.
LIMIT_VARIABLE = "ROVER_COSIM_UNPACK_MAX_BYTES"


class UnpackError(ValueError):
    """An archive that cannot or may not be unpacked; the message names it and why."""


class _Budget:
    """The bytes this process has unpacked so far."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.used = 0

    def take(self, size: int, limit: int, archive: Path) -> None:
        with self.lock:
            if self.used + size > limit:
                raise UnpackError(f"{archive}: unpacking it would take more than {limit} bytes in all (the archives "
                                  f"this command unpacked, nested ones included; {LIMIT_VARIABLE} sets another limit)")
            self.used += size

    def release(self, size: int) -> None:
        with self.lock:
            self.used = max(0, self.used - size)


_BUDGET = _Budget()


def release(size: int) -> None:
    """Give back ``size`` bytes of the budget: a folder unpacked into was removed."""
    _BUDGET.release(size)


def size_limit(variable: str = LIMIT_VARIABLE, default: int = SIZE_LIMIT) -> int:
    """The limit [bytes] the environment ``variable`` sets, else ``default``; UnpackError for a
    value that is not a whole number of bytes > 0."""
    text = os.environ.get(variable)
    if text is None:
        return default
    try:
        limit = int(text)
    except ValueError:
        raise UnpackError(f"{variable} = {text!r}: expected a whole number of bytes") from None
    if limit <= 0:
        raise UnpackError(f"{variable} = {text!r}: expected a number of bytes > 0")
    return limit


def unpack_archive(archive: Path, folder: Path, limit: int | None = None) -> int:
    """Every entry of ``archive`` into ``folder`` (none outside it, no links): at most ``limit``
    bytes of this archive (None: no limit of its own), and all this process unpacks, this
    included, within :func:`size_limit`. Returns the bytes written (:func:`release` them when the
    folder is removed). UnpackError naming the archive otherwise, or when it is not a readable zip
    file or the disk is full."""
    archive = Path(archive)
    total = size_limit()
    own = total if limit is None else min(limit, total)
    try:
        with zipfile.ZipFile(archive) as zf:
            entries = zf.infolist()
            declared = sum(e.file_size for e in entries)
            if declared > own:
                raise UnpackError(f"{archive}: unpacking it would take {declared} bytes: more than the limit of "
                                  f"{own} bytes ({LIMIT_VARIABLE} sets another)")
            folder.mkdir(parents=True, exist_ok=True)
            root = folder.resolve()
            written = 0
            for entry in entries:
                target = (root / entry.filename).resolve()
                if not target.is_relative_to(root) or entry.filename.startswith("/"):
                    raise UnpackError(f"{archive}: entry {entry.filename!r} lies outside the archive's folder")
                if (entry.external_attr >> 16) & 0o170000 == 0o120000:
                    raise UnpackError(f"{archive}: entry {entry.filename!r} is a symbolic link (not allowed)")
                if entry.is_dir():
                    target.mkdir(parents=True, exist_ok=True)
                    continue
                target.parent.mkdir(parents=True, exist_ok=True)
                with zf.open(entry) as source, open(target, "wb") as sink:
                    while chunk := source.read(1 << 20):
                        written += len(chunk)
                        if written > own:
                            raise UnpackError(f"{archive}: more than {own} bytes unpacked: above the limit "
                                              f"({LIMIT_VARIABLE} sets another)")
                        _BUDGET.take(len(chunk), total, archive)
                        sink.write(chunk)
            return written
    except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, NotImplementedError) as error:
        raise UnpackError(f"{archive}: not a readable zip archive ({error})") from None
    except OSError as error:
        raise UnpackError(f"{archive}: cannot be unpacked into {folder}: {error.strerror or error}") from None
