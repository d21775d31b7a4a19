"""The sweep's cache of runs: each run is a CSV written with a checksum beside it, and is only
used when it is whole.

``W575_tau20.csv.gz`` goes with ``W575_tau20.csv.gz.sha256`` (JSON: the case the file was computed for,
its key; SHA-256 of that key and the CSV's bytes together; its rows and columns), both written to
temporary names and renamed, the checksum last. A run file is used only if its checksum file
exists and matches, it was computed for the case it stands for (its key: the file's place in the
cache, whose folders are the digests of the FMU, soil and plan, so a file copied or moved from
another case, with its own checksum, is refused), and it has the expected rows and columns; any
other file is reported (naming it and why) and computed again. Partial files of an
interrupted sweep (``.*.part``) are removed when the next sweep starts.

A file whose name ends in ``.gz`` holds its CSV gzip-compressed (a sweep's runs: a third of the
plain CSV's size; written with a zero timestamp, so the same run gives the same bytes).
"""

from __future__ import annotations

import gzip
import hashlib
import io
import json
import os
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

#: read_csv's options for floats read back exactly (none needed from pandas 3 on, where the option is deprecated)
_ROUND_TRIP: dict[str, str] = {"float_precision": "round_trip"} if int(pd.__version__.split(".")[0]) < 3 else {}


def checksum_file(path: Path) -> Path:
    return path.with_name(path.name + ".sha256")


def _atomic_write(target: Path, data: bytes) -> None:
    handle, temporary = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent)
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(data)
        os.replace(temporary, target)
    finally:
        Path(temporary).unlink(missing_ok=True)


def case_key(path: Path) -> str:
    """The case a cache file stands for: its path below the cache folder (folders named by the
    digests of what it was computed from, and its own name; outside a folder named cache, its
    name and the two folders above it), so that moving the whole results folder keeps it."""
    parts = Path(path).parts
    below = [k for k, part in enumerate(parts[:-1]) if part == "cache"]
    return "/".join(parts[below[-1] + 1:] if below else parts[-3:])


def _digest(key: str, payload: bytes) -> str:
    """SHA-256 of a cache file's key and content together."""
    return hashlib.sha256(key.encode() + b"\n" + payload).hexdigest()


#: gzip's level for the run files: 1 compresses a run (111 kB of CSV) in 0.8 ms to 40 kB, 6 (zlib's
#: default, used before) in 4.4 ms to 37 kB; a sweep writes hundreds of them.
GZIP_LEVEL = 1


def _csv(data: pd.DataFrame, float_format: str | None) -> bytes:
    """``data.to_csv(index=False, float_format=...)``'s bytes; for a table of floats without NaN
    (a run) by one %-format of the whole table, 5x faster than pandas' writer and the same bytes."""
    values = data.to_numpy()
    if (float_format is None or values.dtype != np.float64 or np.isnan(values).any()
            or any("," in str(c) or '"' in str(c) for c in data.columns)):
        return data.to_csv(index=False, float_format=float_format).encode()
    row = ",".join([float_format] * values.shape[1]) + "\n"
    header = ",".join(str(c) for c in data.columns) + "\n"
    return (header + (row * values.shape[0]) % tuple(values.ravel().tolist())).encode()


def write_run(target: Path, data: pd.DataFrame, float_format: str | None = "%.12g") -> None:
    """The run's CSV, then its checksum (so a checksum always describes a whole file, and the
    case it was computed for). ``float_format`` None writes every float exactly (shortest repr
    that reads back the same)."""
    target = Path(target)
    payload = _csv(data, float_format)
    if target.name.endswith(".gz"):
        payload = gzip.compress(payload, compresslevel=GZIP_LEVEL, mtime=0)
    _atomic_write(target, payload)
    key = case_key(target)
    record = {"key": key, "sha256": _digest(key, payload), "rows": len(data), "columns": list(data.columns)}
    _atomic_write(checksum_file(target), json.dumps(record).encode())


def read_run(path: Path, rows: int, columns: list[str], exact: bool = False) -> tuple[pd.DataFrame | None, str | None]:
    """(the run, None) when the file is whole and as expected; (None, why not) otherwise, or
    (None, None) when there is no file at all. ``exact``: every float as written, to the last bit
    (pandas >= 3 reads so by default; older pandas' default parser may be one unit in the last
    place off, and needs its round-trip parser)."""
    path = Path(path)
    check = checksum_file(path)
    if not path.exists():  # never written, or removed on purpose (a checksum left alone goes too)
        check.unlink(missing_ok=True)
        return None, None
    try:
        payload = path.read_bytes()
        record = json.loads(check.read_text())
    except FileNotFoundError as missing:
        return None, f"{Path(missing.filename).name} is missing"
    except (OSError, ValueError) as error:
        return None, f"unreadable checksum ({error})"
    key = case_key(path)
    if not isinstance(record, dict) or "key" not in record:
        return None, "its checksum names no case (a cache of an older version, or not ours)"
    if record["key"] != key:
        return None, f"it was computed for {record['key']!r}, not for {key!r} (copied or moved from another case)"
    if _digest(key, payload) != record.get("sha256"):
        return None, "its content does not match its checksum (cut short or changed)"
    try:
        text = gzip.decompress(payload) if path.name.endswith(".gz") else payload
        data = pd.read_csv(io.BytesIO(text), **_ROUND_TRIP if exact else {})
    except (OSError, EOFError, ValueError, pd.errors.ParserError) as error:
        return None, f"not a readable CSV ({error})"
    if len(data) != rows or not set(columns) <= set(data.columns):
        return None, f"{len(data)} rows and columns {list(data.columns)}; expected {rows} rows with {columns}"
    return data, None


def discard(path: Path) -> None:
    """Remove a run file and its checksum."""
    Path(path).unlink(missing_ok=True)
    checksum_file(Path(path)).unlink(missing_ok=True)


def remove_partial_files(folder: Path) -> list[Path]:
    """The ``.*.part`` files an interrupted sweep left, removed."""
    removed = sorted(Path(folder).glob(".*.part"))
    for path in removed:
        path.unlink(missing_ok=True)
    return removed
