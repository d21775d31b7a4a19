"""A run's rows written as they come (orchestrator.runs.TableStream): its chunks are formatted and
written by a thread of their own while the run goes on, in order; the file is the whole table's
bytes, a chunk the disk refuses keeps it and every later one for the end, and a failure in the
writing thread is raised to the run, not lost."""

from __future__ import annotations

import errno
import threading
from pathlib import Path

import numpy as np
import pytest

from rover_cosim.orchestrator.recorder import Table
from rover_cosim.orchestrator.runs import TableStream, table_bytes


def _chunks(rows: int = 3000, size: int = 700) -> list[Table]:
    rng = np.random.default_rng(5)
    time = np.arange(rows) * 1e-3
    values = rng.standard_normal((rows, 3)) * 10.0 ** rng.integers(-8, 8, (rows, 3))
    flags = rng.random(rows) < 0.5
    return [Table(("time", "a.x", "a.y", "b.z", "b.on"),
                  (time[k:k + size], values[k:k + size, 0], values[k:k + size, 1], values[k:k + size, 2],
                   flags[k:k + size]))
            for k in range(0, rows, size)]


def _whole(chunks: list[Table]) -> Table:
    return Table(chunks[0].names, tuple(np.concatenate([c.columns[j] for c in chunks])
                                        for j in range(len(chunks[0].names))))


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_chunks_written_while_the_run_goes_on_are_the_whole_table(tmp_path: Path, suffix: str):
    chunks = _chunks()
    stream = TableStream(tmp_path / f"out{suffix}")
    names = set()
    original = stream._write

    def recording(table: Table) -> None:
        names.add(threading.current_thread().name)
        original(table)

    stream._write = recording  # type: ignore[method-assign]
    for chunk in chunks:
        stream(chunk)
    assert stream._close() == {}
    assert names and all(name.startswith("rover-cosim-rows") for name in names)
    written = stream.temporary.read_bytes()
    if suffix == ".csv":
        assert written == table_bytes(_whole(chunks), tmp_path / "whole.csv")
    else:
        import pyarrow.parquet as pq

        read = pq.read_table(stream.temporary)
        assert read.column_names == list(chunks[0].names) and read.num_rows == 3000
        np.testing.assert_array_equal(read.column("a.y").to_numpy(), _whole(chunks).columns[2])
    assert stream.rows == 3000 and stream.last_time == pytest.approx(2.999)


def test_a_chunk_the_disk_refuses_keeps_it_and_the_later_ones_for_the_end(tmp_path: Path):
    chunks = _chunks()
    stream = TableStream(tmp_path / "out.csv")
    original, calls = stream._write, []

    def refusing(table: Table) -> None:
        calls.append(len(table))
        if len(calls) == 2:
            raise OSError(errno.ENOSPC, "No space left on device")
        original(table)

    stream._write = refusing  # type: ignore[method-assign]
    for chunk in chunks:
        stream(chunk)
    rest = stream._close()
    assert len(calls) == 2, "after the refusal no chunk is written to the file"
    assert rest == {tmp_path / "out.csv": table_bytes(_whole(chunks), tmp_path / "out.csv")}
    assert not stream.temporary.exists()


def test_an_error_in_the_writing_thread_reaches_the_run(tmp_path: Path):
    stream = TableStream(tmp_path / "out.csv")

    def broken(table: Table) -> None:
        raise ValueError("a column the writer cannot format")

    stream._write = broken  # type: ignore[method-assign]
    stream(_chunks()[0])
    with pytest.raises(ValueError, match="cannot format"):
        stream._close()
    stream.discard()
    assert not stream.temporary.exists()
