"""A co-simulation run written to disk: the recorded trajectories (CSV, or Parquet for long runs)
and a JSON sidecar (the system file, SHA-256 of each FMU, package versions, wall time), both or
neither. CSV values are written at full precision (each reads back equal to the bit); Strings
are quoted where they need it; Parquet keeps every column's type."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from rover_cosim.common.outputs import file_sha256, json_bytes, run_record, write_all

from .isolation import isolated
from .model import System
from .observers import Observer
from .recorder import RunResult, Table


def system_record(system: System) -> dict[str, Any]:
    """What a record says of a system: every FMU (file, SHA-256, GUID, FMI version, interface and
    every parameter and start value set) and every block (type, and its keys where it has them)."""
    return {
        "fmus": {fmu.name: {"path": str(fmu.path), "sha256": file_sha256(fmu.path), "guid": fmu.description.guid,
                            "fmi_version": str(fmu.description.fmiVersion), "interface": fmu.interface,
                            "parameters": dict(fmu.parameters), "start": dict(fmu.start),
                            "isolation": "process" if isolated(fmu, system.fmu_timeout) else "none",
                            **({} if fmu.validation == "strict" else {"validation": fmu.validation,
                                                                      "validation_problems": list(fmu.problems)})}
                 for fmu in system.fmus},
        "blocks": {block.name: block.kind for block in system.blocks},
        "blocks_keys": {block.name: block.keys for block in system.blocks if block.keys is not None},
    }


#: The convention by which participants see input signals (sources), said in every run's record.
INPUT_TIMING = ("every participant stepping from t to t + h sees each input signal (a source block: csv, step, "
                "ramp, ...) at t, held over the step (FMPy's convention; at a repeated time, the later row); a Model "
                "Exchange FMU takes a signal's change at a communication point there, in Event Mode where a discrete "
                "input changes or a signal jumps (a repeated time, a step)")


def sidecar(system: System, result: RunResult, command: str,
            extra: dict[str, Any] | None = None) -> dict[str, object]:
    record = run_record(command, {"algorithm": system.algorithm, "step_s": system.step,
                                  "start_time_s": system.start_time, "stop_time_s": system.stop_time,
                                  "order": system.order, "relative_tolerance": system.relative_tolerance,
                                  "output_interval_s": system.output_interval, "input_timing": INPUT_TIMING,
                                  "fmu_timeout_s": system.fmu_timeout})
    return {
        **record,
        "system_file": str(system.path) if system.path else None,
        "system_sha256": file_sha256(system.path) if system.path else None,
        "settings_from": system.settings_from,
        "stopped": result.stopped,
        **({"notes": list(result.notes)} if result.notes else {}),
        **system_record(system),
        "steps": result.steps,
        "wall_seconds": result.wall_seconds,
        "participant_seconds": result.step_seconds,
        "master_overhead_seconds": result.master_overhead_seconds,
        "columns": list(result.columns),
        "units": {"time": "s", **recorded_units(system)},
        **(extra or {}),
    }


def recorded_units(system: System) -> dict[str, str]:
    """The unit each recorded FMU variable declares (its own, else its type's), by column."""
    units: dict[str, str] = {}
    entries = {fmu.name: fmu for fmu in system.fmus}
    for port in system.record:
        entry = entries.get(port.instance)
        variable = entry.variables().get(port.variable) if entry is not None else None
        unit = getattr(variable, "unit", None) or getattr(getattr(variable, "declaredType", None), "unit", None)
        if unit:
            units[str(port)] = str(unit)
    return units


#: The file types a run's trajectories are written as.
FORMATS = (".csv", ".parquet")


def sidecar_path(csv_path: Path) -> Path:
    """The JSON sidecar of ``csv_path`` (a .csv or .parquet file); ValueError for another suffix."""
    csv_path = Path(csv_path)
    if csv_path.suffix.lower() not in FORMATS:
        raise ValueError(f"output {csv_path}: expected a .csv or .parquet file (its sidecar is the same name "
                         "with .json)")
    return csv_path.with_suffix(".json")


def table_bytes(data: Any, path: Path) -> bytes:
    """``data`` (a recorder's :class:`Table`, or a DataFrame) as the bytes of ``path``'s format:
    CSV at full precision (the shortest text of each float that reads back equal; Arrow's writer,
    ~10x pandas' speed; Booleans as true/false, Strings quoted), or Parquet (pyarrow; every column
    keeps its type)."""
    import io

    import pyarrow as pa

    if isinstance(data, Table):
        table = pa.Table.from_arrays([arrow_column(column) for column in data.columns], names=list(data.names))
    else:
        table = pa.Table.from_pandas(data, preserve_index=False)
    buffer = io.BytesIO()
    if Path(path).suffix.lower() == ".parquet":
        import pyarrow.parquet as pq

        pq.write_table(table, buffer)
        return buffer.getvalue()
    import csv

    import pyarrow.csv as pc

    header = io.StringIO()
    csv.writer(header, lineterminator="\n").writerow([str(c) for c in table.column_names])
    buffer.write(header.getvalue().encode())
    pc.write_csv(table, buffer, pc.WriteOptions(include_header=False, quoting_style="needed"))
    return buffer.getvalue()


class TableStream:
    """A run's rows written to ``path``'s format as they come (a recorder's sink: one call per
    chunk of rows), into a temporary file beside ``path`` that :meth:`publish` renames into place
    with the JSON sidecar (or :meth:`publish_partial` beside it as NAME.partial.*): the memory of
    a run no longer grows with its length. The bytes equal :func:`table_bytes` of the whole table.
    Should the disk refuse a chunk, the rest is kept in memory and the whole saved elsewhere when
    published (``common.outputs.publish`` says where)."""

    def __init__(self, path: Path):
        from rover_cosim.common.outputs import staging_file

        self.path = Path(path)
        handle, self.temporary = staging_file(self.path)
        self.stream: Any = os.fdopen(handle, "wb")
        self.writer: Any = None
        self.rows = 0
        self.last_time: float | None = None
        self.held: list[Table] = []   # chunks the disk refused, and every one after them
        self.failure: OSError | None = None
        # the chunks are formatted and written by one thread of their own, in order, while the run
        # goes on (pyarrow formats without the GIL); only that thread touches the file until _join
        self._writing: Any = None
        self._written: list[Any] = []  # the futures of the chunks handed to it

    def __call__(self, table: Table) -> None:
        if not len(table):
            return
        self.rows += len(table)
        self.last_time = float(table.columns[0][-1])
        if self._writing is None:
            from concurrent.futures import ThreadPoolExecutor

            self._writing = ThreadPoolExecutor(max_workers=1, thread_name_prefix="rover-cosim-rows")
        self._written.append(self._writing.submit(self._keep, table))

    def _keep(self, table: Table) -> None:
        """In the writing thread: the chunk written, or held (the disk refused it or one before)."""
        if self.failure is None:
            try:
                self._write(table)
                return
            except OSError as error:
                self.failure = error
        self.held.append(table)

    def _join(self) -> None:
        """Wait for the chunks handed over so far (a formatting error is raised here)."""
        if self._writing is not None:
            self._writing.shutdown(wait=True)
            self._writing = None
        futures, self._written = self._written, []
        for future in futures:
            future.result()

    def _write(self, table: Table) -> None:
        import pyarrow as pa

        arrow = pa.Table.from_arrays([arrow_column(column) for column in table.columns], names=list(table.names))
        if self.writer is None:
            if self.path.suffix.lower() == ".parquet":
                import pyarrow.parquet as pq

                self.writer = pq.ParquetWriter(self.stream, arrow.schema)
            else:
                import csv
                import io

                import pyarrow.csv as pc

                header = io.StringIO()
                csv.writer(header, lineterminator="\n").writerow([str(c) for c in arrow.column_names])
                self.stream.write(header.getvalue().encode())
                self.writer = pc.CSVWriter(self.stream, arrow.schema,
                                           write_options=pc.WriteOptions(include_header=False, quoting_style="needed"))
        self.writer.write_table(arrow)

    def _close(self) -> dict[Path, bytes]:
        """Close the file; what must still be written as bytes (nothing, unless the disk refused)."""
        self._join()
        try:
            if self.writer is not None:
                self.writer.close()
            self.stream.close()
        except OSError as error:
            self.failure = self.failure or error
        if self.failure is None:
            return {}
        data = self.temporary.read_bytes() if self.temporary.exists() else b""
        for table in self.held:  # what the disk refused: as the rest of the same file
            data = _joined(data, table_bytes(table, self.path), self.path)
        self.temporary.unlink(missing_ok=True)
        return {self.path: data}

    def publish(self, system: System, result: RunResult, command: str = "rover-cosim run",
                extra: dict[str, Any] | None = None) -> list[Path]:
        """The rows at ``path`` and its JSON sidecar, both or neither (``common.outputs.publish``)."""
        from rover_cosim.common.outputs import publish

        rest = self._close()
        record = sidecar(system, result, command, extra)
        publish({} if rest else {self.path: self.temporary}, {**rest, sidecar_path(self.path): json_bytes(record)})
        return [self.path, sidecar_path(self.path)]

    def publish_partial(self, system: System, failure: str, command: str = "rover-cosim run") -> list[Path]:
        """The rows so far as NAME.partial.* with a record saying why the run failed."""
        from rover_cosim.common.outputs import publish

        rest = self._close()
        target = partial_path(self.path)
        record = _partial_record(system, command, failure, self.rows, self.last_time)
        written = {} if rest else {target: self.temporary}
        rows = {target: rest[self.path]} if rest else {}
        publish(written, {**rows, sidecar_path(target): json_bytes(record)}, complete=False)
        return [target, sidecar_path(target)]

    def discard(self) -> None:
        """Remove the temporary file (a run that wrote nothing to keep)."""
        try:
            self._join()
        finally:
            self._discard()

    def _discard(self) -> None:
        try:
            self.stream.close()
        except OSError:
            pass
        self.temporary.unlink(missing_ok=True)


class Publisher(Observer):
    """Publishes a :class:`TableStream`'s file and its sidecar when the run finishes, before its
    FMUs are terminated and freed (a crash or hang there cannot lose a finished run);
    ``written``: the files, once it did."""

    def __init__(self, stream: TableStream, system: System, extra: dict[str, Any] | None = None):
        self.stream, self.system, self.extra = stream, system, extra
        self.written: list[Path] = []

    def finish(self, result: RunResult) -> None:
        self.written = self.stream.publish(self.system, result, extra=self.extra)

    def noted(self, result: RunResult) -> None:
        """The sidecar again, with what went wrong after the results were written (``result.notes``)."""
        if result.notes and self.written:
            write_all({self.written[1]: json_bytes(sidecar(self.system, result, "rover-cosim run", self.extra))})


def _joined(first: bytes, second: bytes, path: Path) -> bytes:
    """Two CSV texts of the same columns as one (the second's header dropped); Parquet is not
    joined (the first file, whole, is kept: the rows after it are lost with the disk)."""
    if path.suffix.lower() == ".parquet" or not first:
        return first or second
    return first + second.split(b"\n", 1)[1]


def arrow_column(values: np.ndarray) -> Any:
    """A recorded column as an Arrow array over the same memory, built from its buffers: pyarrow's
    converters (``pa.array``) import pandas (0.15-0.25 s) to ask whether the values are a Series."""
    import pyarrow as pa

    n = len(values)
    if values.dtype == bool:
        return pa.Array.from_buffers(pa.bool_(), n, [None, pa.py_buffer(np.packbits(values, bitorder="little"))])
    if values.dtype == object:  # text
        encoded = [str(v).encode() for v in values]
        offsets = np.zeros(n + 1, dtype=np.int64)
        np.cumsum([len(e) for e in encoded], out=offsets[1:])
        return pa.Array.from_buffers(pa.large_string(), n, [None, pa.py_buffer(offsets),
                                                            pa.py_buffer(b"".join(encoded))])
    values = np.ascontiguousarray(values)
    return pa.Array.from_buffers(pa.from_numpy_dtype(values.dtype), n, [None, pa.py_buffer(values)])


def partial_path(csv_path: Path) -> Path:
    """Where a failed run's rows go: ``NAME.partial.csv`` beside ``NAME.csv``."""
    csv_path = Path(csv_path)
    return csv_path.with_name(f"{csv_path.stem}.partial{csv_path.suffix}")


def _partial_record(system: System, command: str, failure: str, rows: int,
                    last_time: float | None) -> dict[str, Any]:
    record = run_record(command, {"algorithm": system.algorithm, "step_s": system.step,
                                  "stop_time_s": system.stop_time})
    record.update({"partial": True, "failure": failure, "rows": rows, "last_time_s": last_time,
                   "system_file": str(system.path) if system.path else None})
    return record


