"""Memory bounded by the output (issue 45): `rover-cosim run` hands its rows to the file in
chunks as the run goes (recorder.CHUNK_ROWS at a time), so that a long run holds a chunk, not the
run; the file is the same, byte for byte, as the whole table written at once (CSV; Parquet: the
same table, in row groups,
with and without an output interval, stepped natively or in Python), and a run that fails keeps
its rows, chunks already written included, as NAME.partial.csv."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from c_fmu import built_or_skip
from integrator_fmu import build_integrator
from misbehave_fmu import MODES, build_misbehave

from rover_cosim.cli import main
from rover_cosim.orchestrator import SystemBuilder, recorder, run
from rover_cosim.orchestrator.runs import table_bytes

#: Rows per chunk in these tests: the recorder's own 8,192 asked for runs of 16,500 steps (5 s
#: through a process-isolated FMU); chunking does not depend on the size.
CHUNK_ROWS = 600


@pytest.fixture(autouse=True)
def small_chunks(monkeypatch: pytest.MonkeyPatch) -> None:
    assert recorder.CHUNK_ROWS > CHUNK_ROWS
    monkeypatch.setattr(recorder, "CHUNK_ROWS", CHUNK_ROWS)


@pytest.fixture(scope="module")
def integrator(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return built_or_skip(build_integrator(tmp_path_factory.mktemp("integrator")))


@pytest.fixture(scope="module")
def misbehave(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return built_or_skip(build_misbehave(tmp_path_factory.mktemp("misbehave")))


@pytest.mark.parametrize(("suffix", "interval", "isolation"), [(".csv", None, "none"), (".csv", 0.003, "none"),
                                                                (".parquet", None, "none"),
                                                                (".csv", None, "process")])
def test_a_run_written_in_chunks_is_the_whole_table_byte_for_byte(integrator, tmp_path, suffix, interval, isolation):
    steps = 2 * CHUNK_ROWS + 123  # three chunks, the last one short
    builder = SystemBuilder("chunks").simulation(stop_time=steps * 1e-3, step=1e-3, output_interval=interval)
    builder.add_fmu("model", integrator, start={"k": 3, "u": 0.5}, isolation=isolation)
    system = builder.build()
    whole = table_bytes(run(system).table, Path(f"x{suffix}"))
    toml = tmp_path / "chunks.toml"
    from rover_cosim.orchestrator.system import system_to_toml

    toml.write_text(system_to_toml(system, tmp_path))
    out = tmp_path / f"out{suffix}"
    assert main(["run", str(toml), "-q", "-o", str(out)]) == 0
    if suffix == ".csv":
        assert out.read_bytes() == whole
    else:  # a row group per chunk: other bytes, the same table (values and types)
        import io

        import pyarrow.parquet as pq

        assert pq.read_table(out).equals(pq.read_table(io.BytesIO(whole)))
    assert not [p.name for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary left


def test_a_failed_long_run_keeps_every_chunk_as_partial(misbehave, tmp_path, capsys):
    at = 2.5 * CHUNK_ROWS * 1e-3  # the crash comes after two chunks were handed over
    out = tmp_path / "out.csv"
    code = main(["run", str(misbehave), "-q", "-o", str(out), "--step", "1e-3", "--stop-time", "30",
                 "--start", f"mode={MODES['segfault']}", "--start", f"at={at}"])
    assert code == 1 and not out.exists()
    partial = np.loadtxt(tmp_path / "out.partial.csv", delimiter=",", skiprows=1)
    expected = round(at / 1e-3) + 1
    assert len(partial) == expected and f"the {expected} rows computed before it" in capsys.readouterr().err
    np.testing.assert_allclose(partial[:, 1], partial[:, 0], atol=1e-9)  # x = time, every row
    assert not [p.name for p in tmp_path.iterdir() if p.name.startswith(".")]
