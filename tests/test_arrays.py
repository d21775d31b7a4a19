"""FMI 3.0 arrays (issue 44, item 2): recorded as one column per element (``y[1]``, ``m[1,2]``:
1-based, row-major), settable as start values and connectable element by element; a whole array
named where a scalar is expected is refused naming its elements. On an own FMI 3.0 FMU
(tests/fmus/arrays3.c: y = gain u + offset, m = [[t, 2t], [3t, 4t]], k = [steps, -steps]),
row for row against FMPy."""

from __future__ import annotations

from pathlib import Path

import fmpy
import numpy as np
import pandas as pd
import pytest
from arrays_fmu import build_arrays
from c_fmu import built_or_skip

from rover_cosim.cli import main
from rover_cosim.orchestrator import SystemBuilder, run
from rover_cosim.orchestrator.blocks import Constant
from rover_cosim.orchestrator.model import SystemFileError


@pytest.fixture(scope="module")
def arrays(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return built_or_skip(build_arrays(tmp_path_factory.mktemp("arrays")))


def test_every_element_is_a_column_and_the_rows_are_fmpys(arrays, tmp_path):
    csv = tmp_path / "u.csv"
    csv.write_text("time,u[1],u[2],u[3]\n0,1,2,3\n1,2,4,6\n")
    out = tmp_path / "a.csv"
    assert main(["run", str(arrays), "--input", str(csv), "--start", "gain=3", "--start", "offset[2]=5",
                 "-o", str(out), "--quiet"]) == 0
    ours = pd.read_csv(out)
    assert list(ours.columns) == ["time", "model.y[1]", "model.y[2]", "model.y[3]", "model.m[1,1]", "model.m[1,2]",
                                  "model.m[2,1]", "model.m[2,2]", "model.k[1]", "model.k[2]", "model.s"]
    signals = np.array([(0.0, (1.0, 2.0, 3.0)), (1.0, (2.0, 4.0, 6.0))], dtype=[("time", float), ("u", float, (3,))])
    theirs = fmpy.simulate_fmu(str(arrays), input=signals, stop_time=1.0, output_interval=0.1,
                               start_values={"gain": 3.0, "offset": [1.0, 5.0, 3.0]})
    np.testing.assert_allclose(ours[["model.y[1]", "model.y[2]", "model.y[3]"]].to_numpy(), theirs["y"], atol=1e-12)
    np.testing.assert_allclose(ours[["model.m[1,1]", "model.m[1,2]", "model.m[2,1]", "model.m[2,2]"]].to_numpy(),
                               theirs["m"].reshape(len(theirs), 4), atol=1e-12)
    np.testing.assert_array_equal(ours[["model.k[1]", "model.k[2]"]].to_numpy(), theirs["k"])
    np.testing.assert_allclose(ours["model.s"], theirs["s"], atol=1e-12)
    assert ours["model.y[2]"].iloc[0] == 3 * 2 + 5 and ours["model.m[1,2]"].iloc[-1] == pytest.approx(2.0)


def test_array_elements_connect_one_by_one_and_the_others_keep_their_values(arrays):
    """a.y[3] drives b.u[1]; b.u[2] from a block; b.u[3] keeps its start (0)."""
    builder = SystemBuilder("two").simulation(stop_time=0.3, step=0.1, algorithm="jacobi")
    builder.add_fmu("a", arrays, start={"u[1]": 1.0, "u[2]": 1.0, "u[3]": 1.0})
    builder.add_fmu("b", arrays, parameters={"gain": 1.0, "offset[1]": 0.0, "offset[2]": 0.0, "offset[3]": 0.0})
    builder.add_block("two", Constant("two", 2.0))
    builder.connect("a.y[3]", "b.u[1]").connect("two.y", "b.u[2]")
    data = run(builder.record("b.y[1]", "b.y[2]", "b.y[3]", "b.s").build()).data
    assert data["b.y[1]"].iloc[-1] == 2 * 1.0 + 3 and data["b.y[2]"].iloc[-1] == 2.0 and data["b.y[3]"].iloc[-1] == 0
    assert data["b.s"].iloc[-1] == 5.0 + 2.0


def test_a_whole_array_where_a_scalar_goes_is_refused_naming_its_elements(arrays):
    builder = SystemBuilder("whole").simulation(stop_time=0.1, step=0.1)
    builder.add_fmu("a", arrays)
    with pytest.raises(SystemFileError, match=r"a\.y is an array \(FMI 3.0 dimensions\): name its elements, "
                                              r"y\[1\] \.\.\. y\[3\]"):
        builder.record("a.y")
    with pytest.raises(SystemFileError, match=r"a\.m is an array .* m\[1,1\] \.\.\. m\[2,2\]"):
        builder.set_start("a", {"m": 1.0})


def test_record_patterns_reach_array_elements(arrays, tmp_path):
    out = tmp_path / "m.csv"
    assert main(["run", str(arrays), "--record", "m[[]2,*", "--record", "k[1]", "-o", str(out), "--quiet"]) == 0
    assert list(pd.read_csv(out).columns) == ["time", "model.m[2,1]", "model.m[2,2]", "model.k[1]"]
    # an array's own name records its elements (as FMPy's output= does)
    assert main(["run", str(arrays), "--record", "m", "-o", str(out), "--quiet", "--overwrite"]) == 0
    assert [c for c in pd.read_csv(out).columns if c != "time"] == ["model.m[1,1]", "model.m[1,2]", "model.m[2,1]",
                                                                   "model.m[2,2]"]
