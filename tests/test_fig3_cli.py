import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from rover_cosim import cli
from rover_cosim.common.outputs import write_all
from rover_cosim.jobs import fig3


def test_fig3_writes_csv_png_and_record(tmp_path, capsys):
    assert cli.main(["fig3", "--out", str(tmp_path)]) == 0
    table = pd.read_csv(tmp_path / "fig3_fx_vs_slip.csv")
    assert list(table.columns) == ["load_N", "slip", "sinkage_m", "Fx_N", "Fz_N", "Tx_Nm"]
    assert sorted(table["load_N"].unique()) == [100.0 * i for i in range(1, 9)]
    assert table["slip"].min() == 0.0 and table["slip"].max() == pytest.approx(0.9)
    assert len(table) == 8 * 91
    np.testing.assert_allclose(table["Fz_N"], table["load_N"], rtol=1e-6)
    assert (table["sinkage_m"] > 0).all()
    assert (tmp_path / "fig3_fx_vs_slip.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    record = json.loads((tmp_path / "fig3_fx_vs_slip.json").read_text())
    assert record["command"] == "rover-cosim fig3"
    assert record["parameters"]["soil"]["kphi"] == 8.14e5
    assert "wrote" in capsys.readouterr().out
    assert not list(tmp_path.glob(".*.part"))


def test_custom_loads_and_step(tmp_path):
    assert cli.main(["fig3", "--out", str(tmp_path), "--loads", "275,575", "--slip-step", "0.3"]) == 0
    table = pd.read_csv(tmp_path / "fig3_fx_vs_slip.csv")
    assert sorted(table["load_N"].unique()) == [275.0, 575.0]
    np.testing.assert_allclose(sorted(table["slip"].unique()), [0.0, 0.3, 0.6, 0.9])


@pytest.mark.parametrize("args, message", [
    (["--loads", "100,-5"], "load=-5.0 N"),
    (["--loads", "heavy"], "loads='heavy'"),
    (["--slip-step", "0"], "slip step=0.0"),
])
def test_bad_arguments_are_named(tmp_path, capsys, args, message):
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["fig3", "--out", str(tmp_path), *args])
    assert exit_info.value.code == 2
    assert message in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


def test_load_the_wheel_cannot_carry_fails_cleanly(tmp_path, capsys):
    assert cli.main(["fig3", "--out", str(tmp_path), "--loads", "100,1e7"]) == 2
    assert "load=10000000.0 N" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


def test_failed_drawing_leaves_previous_results_untouched(tmp_path, monkeypatch):
    old = tmp_path / "fig3_fx_vs_slip.csv"
    old.write_text("previous\n")

    def broken(table, soil=""):
        raise RuntimeError("renderer failed")

    monkeypatch.setattr(fig3, "fig3_figure", broken)
    with pytest.raises(RuntimeError, match="renderer failed"):
        fig3.write_fig3(tmp_path)
    assert old.read_text() == "previous\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fig3_fx_vs_slip.csv"]


def test_write_all_is_all_or_nothing_and_saves_what_it_could_not_write(tmp_path, monkeypatch):
    import re
    import tempfile

    from rover_cosim.common.outputs import OutputError

    (tmp_path / "tmp").mkdir()
    monkeypatch.setenv("TMPDIR", str(tmp_path / "tmp"))
    monkeypatch.setattr(tempfile, "tempdir", None)
    out = tmp_path / "out"
    out.mkdir()
    blocker = out / "not_a_dir"
    blocker.write_text("x")
    with pytest.raises(OutputError, match=rf"could not be written to {out} \(.*\); they are saved in ") as failed:
        write_all({out / "a.csv": b"1", blocker / "b.csv": b"2"})
    assert sorted(p.name for p in out.iterdir()) == ["not_a_dir"]
    saved = Path(re.search(r"saved in (\S+):", str(failed.value)).group(1))  # type: ignore[union-attr]
    assert saved.parent == tmp_path / "tmp"
    assert (saved / "a.csv").read_bytes() == b"1" and (saved / "not_a_dir" / "b.csv").read_bytes() == b"2"


def test_a_slip_range_with_braking_and_files_named_by_the_soil(tmp_path):
    """Negative slip (braking) mirrors driving in sign; another soil's files sit beside the paper's
    (names carry the soil, and a --set change its digest) instead of replacing them."""
    assert cli.main(["fig3", "--out", str(tmp_path), "--loads", "400", "--slip-range=-0.5,0.5",
                     "--slip-step", "0.25"]) == 0
    assert cli.main(["fig3", "--out", str(tmp_path), "--loads", "400", "--soil", "lete_sand"]) == 0
    assert cli.main(["fig3", "--out", str(tmp_path), "--loads", "400", "--set", "soil.c=500"]) == 0
    names = sorted(p.name for p in tmp_path.iterdir())
    assert {"fig3_fx_vs_slip.csv", "fig3_fx_vs_slip_lete_sand.csv", "fig3_fx_vs_slip_lete_sand.png"} <= set(names)
    assert len([n for n in names if n.startswith("fig3_fx_vs_slip_set-") and n.endswith(".json")]) == 1
    table = pd.read_csv(tmp_path / "fig3_fx_vs_slip.csv")
    np.testing.assert_allclose(table["slip"], [-0.5, -0.25, 0.0, 0.25, 0.5])
    fx = table["Fx_N"].to_numpy()
    assert fx[0] < fx[1] < 0 < fx[3] < fx[4]   # braking pulls back, driving pushes
    record = json.loads((tmp_path / "fig3_fx_vs_slip_lete_sand.json").read_text())
    assert record["parameters"]["choice"]["soil"]["name"] == "lete_sand"


@pytest.mark.parametrize("args, message", [
    (["--slip-range=0.5,0.2"], "expected -1 <= FIRST < LAST <= 1"),
    (["--slip-range=-2,0.5"], "expected -1 <= FIRST < LAST <= 1"),
    (["--slip-range", "one"], "expected FIRST,LAST"),
])
def test_bad_slip_ranges_are_named(tmp_path, capsys, args, message):
    with pytest.raises(SystemExit):
        cli.main(["fig3", "--out", str(tmp_path), *args])
    assert message in capsys.readouterr().err


def test_figures_in_other_formats_and_at_a_chosen_resolution(tmp_path, capsys):
    from PIL import Image

    from rover_cosim.common import figures

    try:
        assert cli.main(["--figures", "png,svg,pdf", "--dpi", "60", "fig3", "--out", str(tmp_path / "a"),
                         "--loads", "300", "--slip-step", "0.3"]) == 0
        assert (tmp_path / "a" / "fig3_fx_vs_slip.svg").read_bytes().lstrip().startswith(b"<?xml")
        assert (tmp_path / "a" / "fig3_fx_vs_slip.pdf").read_bytes().startswith(b"%PDF")
        small = Image.open(tmp_path / "a" / "fig3_fx_vs_slip.png").size
    finally:
        figures.configure()  # this process's settings back to PNG only
    assert cli.main(["fig3", "--out", str(tmp_path / "b"), "--loads", "300", "--slip-step", "0.3"]) == 0
    assert not (tmp_path / "b" / "fig3_fx_vs_slip.svg").exists()
    assert Image.open(tmp_path / "b" / "fig3_fx_vs_slip.png").size[0] > 2 * small[0]  # 150 dpi against 60
    assert cli.main(["--dpi", "5", "fig3", "--out", str(tmp_path / "c")]) == 2
    assert "dpi 5.0: expected 20 to 1200" in capsys.readouterr().err


def test_two_writers_of_the_same_files_leave_one_set_never_a_mix(tmp_path, monkeypatch):
    """Two commands writing r.csv and r.json at once (a delay between the renames, where the mix
    happened): the pair on disk is always one writer's (the renames are under the folder's lock)."""
    import os
    import threading
    import time

    from rover_cosim.common import outputs

    real_replace = os.replace

    def slow_replace(source, target):  # noqa: ANN001 - os.replace's arguments
        slow = Path(target).suffix == ".csv" and Path(source).read_bytes().startswith(b"A")
        real_replace(source, target)
        if slow:  # writer A waits between its two renames: B's pair lands in between
            time.sleep(0.02)

    monkeypatch.setattr(outputs.os, "replace", slow_replace)
    csv, record = tmp_path / "r.csv", tmp_path / "r.json"
    for round_ in range(20):
        writers = [threading.Thread(target=write_all, args=({csv: f"{t}{round_}".encode(),
                                                              record: f"{t}{round_}".encode()},))
                   for t in "AB"]
        writers[0].start()
        time.sleep(0.005)
        writers[1].start()
        for writer in writers:
            writer.join()
        assert csv.read_bytes() == record.read_bytes(), round_


def test_a_second_command_on_the_same_results_is_refused_naming_the_first(tmp_path, capsys):
    import os

    from rover_cosim.common.outputs import writing

    out = tmp_path / "results"
    with writing(out, "rover-cosim identify"):
        assert cli.main(["fig3", "--out", str(out), "--loads", "300", "--slip-step", "0.3"]) == 2
        err = capsys.readouterr().err
        assert f"is being written by PID {os.getpid()} (rover-cosim identify)" in err
        assert not out.exists()
    assert cli.main(["fig3", "--out", str(out), "--loads", "300", "--slip-step", "0.3"]) == 0  # free again


def test_a_long_line_is_thinned_to_its_bins_extremes_and_ends():
    """common.figures.thinned: a 20,001-sample line becomes ~4,000 points holding every bin's
    smallest and largest value (a one-sample spike survives), the first and last samples, in order;
    a short line comes back whole."""
    from rover_cosim.common.figures import LINE_POINTS, thinned

    t = np.arange(20001) * 1e-3
    y = np.sin(t)
    y[12345], y[777] = 50.0, -50.0  # spikes one sample wide
    tx, ty = thinned(t, y)
    assert len(tx) <= LINE_POINTS + 4 and len(tx) >= LINE_POINTS // 2
    assert np.all(np.diff(tx) > 0) and tx[0] == t[0] and tx[-1] == t[-1]
    assert ty.max() == 50.0 and ty.min() == -50.0 and 12.345 in tx and 0.777 in tx
    np.testing.assert_array_equal(ty, y[np.searchsorted(t, tx)])  # samples of the line, not new values
    short_t, short_y = thinned(t[:100], y[:100])
    np.testing.assert_array_equal(short_y, y[:100])
