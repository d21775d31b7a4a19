"""The sweep's cache of runs: each run is a CSV written with a checksum beside it, and is only
used when it is whole.

``W575_tau20.csv`` goes with ``W575_tau20.csv.sha256`` (JSON: SHA-256 of the CSV's bytes, its
rows and columns), both written to temporary names and renamed, the checksum last. A run file is
used only if its checksum file exists and matches, and it has the expected rows and columns; any
other file is reported (a warning naming it and why) and computed again. Partial files of an
interrupted sweep (``.*.part``) are removed when the next sweep starts.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import tempfile
from pathlib import Path

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


def write_run(target: Path, data: pd.DataFrame, float_format: str | None = "%.12g") -> None:
    """The run's CSV, then its checksum (so a checksum always describes a whole file).
    ``float_format`` None writes every float exactly (shortest repr that reads back the same)."""
    target = Path(target)
    payload = data.to_csv(index=False, float_format=float_format).encode()
    _atomic_write(target, payload)
    record = {"sha256": hashlib.sha256(payload).hexdigest(), "rows": len(data), "columns": list(data.columns)}
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
    if not isinstance(record, dict) or hashlib.sha256(payload).hexdigest() != record.get("sha256"):
        return None, "its content does not match its checksum (cut short or changed)"
    try:
        data = pd.read_csv(io.BytesIO(payload), **_ROUND_TRIP if exact else {})
    except (ValueError, pd.errors.ParserError) as error:
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
