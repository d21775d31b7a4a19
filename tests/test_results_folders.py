"""Results folders written as one unit (common.folders, common.outputs.write_all): a process
killed at any point of a write leaves the old result set or the new one, never a mix, and the
run cache inside the folder is kept; output paths checked before the work; results saved
elsewhere (and named) when the folder cannot take them after the work; a signal after the
results are written does not change the exit code 0."""

from __future__ import annotations

import errno
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import pytest

from rover_cosim import cli
from rover_cosim.common import folders, outputs
from rover_cosim.common.outputs import write_all

FIG3 = ["fig3", "--loads", "300", "--slip-step", "0.3"]


def _result(folder: Path, tag: str) -> dict[Path, bytes]:
    return {folder / "r.csv": tag.encode(), folder / "r.json": tag.encode(), folder / "fig_a.png": tag.encode()}


def _tree(folder: Path) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_results_folder_is_replaced_as_one_unit_keeping_its_cache(tmp_path):
    out = tmp_path / "out"
    write_all(_result(out, "A"), folder=out)
    (out / "cache" / "abc").mkdir(parents=True)
    (out / "cache" / "abc" / "run.csv").write_text("cached")
    (out / "other.csv").write_text("another result set of the command")
    before = os.stat(out).st_ino
    write_all({out / "r.csv": b"B", out / "r.json": b"B"}, folder=out, stale=("fig_*",))
    assert os.stat(out).st_ino != before  # a new folder took the old one's place
    assert _tree(out) == {"r.csv": b"B", "r.json": b"B", "other.csv": b"another result set of the command",
                          "cache/abc/run.csv": b"cached"}  # fig_a.png was of the old set: gone
    assert (out / "r.csv").stat().st_mode & 0o777 == outputs.result_mode()
    assert not [p for p in tmp_path.iterdir() if p.name != "out"]  # no sibling left


def test_a_shared_folder_is_written_file_by_file_and_keeps_its_folders(tmp_path):
    out = tmp_path / "results"
    (out / "identification").mkdir(parents=True)
    (out / "identification" / "runs.csv").write_text("identify's")
    before = os.stat(out).st_ino
    assert not folders.swappable(out)
    write_all(_result(out, "A"), folder=out)
    assert os.stat(out).st_ino == before
    assert _tree(out) == {"r.csv": b"A", "r.json": b"A", "fig_a.png": b"A", "identification/runs.csv": b"identify's"}


# The writer kills itself (SIGKILL: nothing of it runs after) at one point of the second write.
KILLERS = {
    "while writing the new files": "real = Path.write_bytes\n"
                                   "def patched(self, data):\n"
                                   "    real(self, data)\n"
                                   "    os.kill(os.getpid(), signal.SIGKILL)\n"
                                   "Path.write_bytes = patched\n",
    "while linking the old folder": "real = os.link\n"
                                    "def patched(*a, **k):\n"
                                    "    real(*a, **k)\n"
                                    "    os.kill(os.getpid(), signal.SIGKILL)\n"
                                    "os.link = patched\n",
    "just before the exchange": "def patched(*a):\n"
                                "    os.kill(os.getpid(), signal.SIGKILL)\n"
                                "folders.exchange = patched\n",
    "just after the exchange": "real = folders.exchange\n"
                               "def patched(*a):\n"
                               "    real(*a)\n"
                               "    os.kill(os.getpid(), signal.SIGKILL)\n"
                               "folders.exchange = patched\n",
}


@pytest.mark.parametrize("moment", list(KILLERS))
def test_a_writer_killed_at_any_point_leaves_one_whole_set_and_the_cache(tmp_path, moment):
    out = tmp_path / "out"
    write_all(_result(out, "A"), folder=out)
    (out / "cache").mkdir()
    (out / "cache" / "run.csv").write_text("cached")
    script = ("import os, signal\nfrom pathlib import Path\nfrom rover_cosim.common import folders\n"
              "from rover_cosim.common.outputs import write_all\n" + KILLERS[moment] +
              f"out = Path({str(out)!r})\n"
              "write_all({out / 'r.csv': b'B', out / 'r.json': b'B', out / 'fig_a.png': b'B'}, folder=out)\n")
    writer = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert writer.returncode == -signal.SIGKILL, writer.stderr
    tree = _tree(out)
    assert tree.pop("cache/run.csv") == b"cached"
    tag = "B" if moment == "just after the exchange" else "A"
    assert tree == {"r.csv": tag.encode(), "r.json": tag.encode(), "fig_a.png": tag.encode()}
    write_all(_result(out, "C"), folder=out)  # the next writer removes what the killed one left
    assert _tree(out)["r.csv"] == b"C" and _tree(out)["cache/run.csv"] == b"cached"
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


def test_where_folders_cannot_be_exchanged_the_files_are_renamed(tmp_path, monkeypatch):
    out = tmp_path / "out"
    write_all(_result(out, "A"), folder=out)
    monkeypatch.setattr(folders, "_renameat2", lambda: None)
    before = os.stat(out).st_ino
    write_all(_result(out, "B"), folder=out)
    assert os.stat(out).st_ino == before and _tree(out)["r.json"] == b"B"
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


def test_an_output_folder_that_cannot_be_written_is_named_before_the_work(tmp_path):
    """A read-only folder (for root, who may write anywhere, the command runs as nobody)."""
    folder = Path(tempfile.mkdtemp(prefix="rover-cosim-test-readonly."))
    try:
        os.chmod(folder, 0o555)
        command = [sys.executable, "-P", "-m", "rover_cosim", *FIG3, "--out", str(folder / "figures")]
        if os.geteuid() == 0:
            if not Path("/usr/bin/setpriv").exists():
                pytest.skip("running as root without setpriv: a read-only folder is writable for root")
            command = ["/usr/bin/setpriv", "--reuid=65534", "--regid=65534", "--clear-groups", *command]
        done = subprocess.run(command, capture_output=True, text=True, timeout=120, cwd="/")
        assert done.returncode == 2, done.stderr
        assert done.stderr.strip().splitlines()[-1] == (
            f"rover-cosim fig3: --out {folder / 'figures'}: the folder {folder} cannot be written (Permission denied)")
        assert not any(folder.iterdir())
    finally:
        os.chmod(folder, 0o755)
        folder.rmdir()


def test_too_little_free_space_is_named_before_the_work(tmp_path, monkeypatch, capsys):
    import shutil

    usage = shutil._ntuple_diskusage(10**9, 10**9 - 10**6, 10**6)  # total, used, free
    monkeypatch.setattr(outputs.shutil, "disk_usage", lambda path: usage)
    assert cli.main(["identify", "--out", str(tmp_path / "ident")]) == 2
    assert capsys.readouterr().err.strip() == (f"rover-cosim identify: --out {tmp_path / 'ident'}: 1.0 MB free on the "
                                               f"file system of {tmp_path}; the results need about 80.0 MB")
    assert not (tmp_path / "ident").exists()


def test_results_that_cannot_be_written_after_the_work_are_saved_and_named(tmp_path, monkeypatch, capsys):
    (tmp_path / "tmp").mkdir()
    monkeypatch.setenv("TMPDIR", str(tmp_path / "tmp"))
    monkeypatch.setattr(tempfile, "tempdir", None)
    assert cli.main([*FIG3, "--out", str(tmp_path / "good")]) == 0
    capsys.readouterr()

    def full(folder, write, stale=()):  # noqa: ANN001, ANN202 - exchange_folder's arguments
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(folder))

    monkeypatch.setattr(outputs, "exchange_folder", full)
    out = tmp_path / "figures"
    assert cli.main([*FIG3, "--out", str(out)]) == 1
    err = capsys.readouterr().err.strip()
    found = re.fullmatch(rf"rover-cosim fig3: the results could not be written to {out} \(No space left on device: "
                         rf"{out}\); they are saved in (\S+): move them where they belong", err)
    assert found, err
    saved = Path(found.group(1))
    assert saved.parent == tmp_path / "tmp" and not out.exists()
    good = _tree(tmp_path / "good")
    assert sorted(_tree(saved)) == sorted(good)
    assert _tree(saved)["fig3_fx_vs_slip.csv"] == good["fig3_fx_vs_slip.csv"]


def _fig3_process(out: Path, hook: str) -> subprocess.CompletedProcess:
    """`rover-cosim fig3` as its own process, with ``hook`` run first (it patches what it needs)."""
    script = ("import os, signal, sys\nfrom rover_cosim import cli\nfrom rover_cosim.common import folders\n"
              "import rover_cosim.jobs.fig3 as fig3\n" + hook +
              f"sys.argv = ['rover-cosim', *{FIG3!r}, '--out', {str(out)!r}]\n"
              "code = cli.main()\n"
              "os.kill(os.getpid(), signal.SIGINT)\n"  # and one more once main returned
              "sys.exit(code)\n")
    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("name", ["SIGINT", "SIGTERM"])
def test_a_signal_after_the_results_are_written_leaves_exit_code_0(tmp_path, name):
    # The signal goes to the main thread itself (os.kill may hand it to another thread, whose
    # handler flag the main thread might not see before the process ends).
    hook = ("import threading\n"
            "real = fig3.write_all\n"
            "def patched(*a, **k):\n"
            "    real(*a, **k)\n"
            f"    signal.pthread_kill(threading.main_thread().ident, signal.{name})\n"
            "fig3.write_all = patched\n")
    done = _fig3_process(tmp_path / "out", hook)
    assert done.returncode == 0, done.stderr
    assert "interrupted after its results were written; they are whole" in done.stderr
    assert (tmp_path / "out" / "fig3_fx_vs_slip.csv").is_file()


def test_a_signal_during_the_exchange_waits_for_it(tmp_path):
    """The signal arrives just before the folder exchange: it is held until the exchange is done
    (the results are whole and the code 0), not raised in the middle of the write."""
    hook = ("real = folders.exchange\n"
            "def patched(*a):\n"
            "    os.kill(os.getpid(), signal.SIGINT)\n"
            "    return real(*a)\n"
            "folders.exchange = patched\n")
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "fig3_fx_vs_slip.csv").write_text("old")  # an earlier result of fig3 (its record says so)
    (tmp_path / "out" / "fig3_fx_vs_slip.json").write_text('{"command": "rover-cosim fig3"}')
    done = _fig3_process(tmp_path / "out", hook)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out" / "fig3_fx_vs_slip.csv").read_text() != "old"


def test_a_signal_before_the_results_are_written_exits_130_and_writes_nothing(tmp_path):
    hook = ("def patched(*a, **k):\n"
            "    os.kill(os.getpid(), signal.SIGTERM)\n"
            "fig3.write_all = patched\n")
    done = _fig3_process(tmp_path / "out", hook)
    assert done.returncode == 130, done.stderr
    assert "rover-cosim fig3: interrupted; nothing more written" in done.stderr
    assert not (tmp_path / "out").exists()


def test_a_folder_whose_parent_cannot_be_written_is_written_file_by_file(tmp_path, monkeypatch):
    out = tmp_path / "out"
    write_all(_result(out, "A"), folder=out)

    def refused(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202 - mkdtemp's arguments
        raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(tmp_path))

    monkeypatch.setattr(folders.tempfile, "mkdtemp", refused)
    before = os.stat(out).st_ino
    write_all(_result(out, "B"), folder=out)
    assert os.stat(out).st_ino == before and _tree(out) == {"r.csv": b"B", "r.json": b"B", "fig_a.png": b"B"}


def test_a_cache_folder_that_is_a_file_is_named_before_the_work(tmp_path, capsys):
    cache = tmp_path / "cache"
    cache.write_text("x")
    assert cli.main(["identify", "--out", str(tmp_path / "ident"), "--cache", str(cache)]) == 2
    assert capsys.readouterr().err.strip() == f"rover-cosim identify: --cache {cache}: is a file: expected a folder " \
                                              "(absent or existing)"


def test_only_complete_results_count_as_written(tmp_path):
    """The rows kept of a failed run (complete=False) do not make a later signal exit 0."""
    before = outputs.committed()
    write_all({tmp_path / "run.partial.csv": b"t\n0\n"}, complete=False)
    assert outputs.committed() == before
    write_all(_result(tmp_path / "out", "A"), folder=tmp_path / "out")
    write_all({tmp_path / "run.csv": b"t\n0\n"})
    assert outputs.committed() == before + 2


def test_an_import_cut_short_by_a_signal_is_an_interruption_not_a_traceback(monkeypatch, capsys):
    """A signal during the import of a C extension (matplotlib's ft2font, a pybind11 module)
    arrives as ImportError("initialization failed") raised from the KeyboardInterrupt."""
    def import_cut_short(args):  # noqa: ANN001, ANN202 - a command's signature
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as interrupt:
            raise ImportError("initialization failed") from interrupt

    monkeypatch.setitem(cli.COMMANDS, "blocks", replace(cli.COMMANDS["blocks"], run=import_cut_short))
    assert cli.main(["blocks"]) == 130
    assert capsys.readouterr().err == "rover-cosim blocks: interrupted; nothing more written\n"

    def import_broken(args):  # noqa: ANN001, ANN202
        raise ImportError("no module named nowhere")

    monkeypatch.setitem(cli.COMMANDS, "blocks", replace(cli.COMMANDS["blocks"], run=import_broken))
    with pytest.raises(ImportError, match="nowhere"):  # a real import error is not hidden as an interruption
        cli.main(["blocks"])


def test_lock_files_are_removed_and_still_exclude(tmp_path, monkeypatch, capsys):
    """Before: every output path ever written left a lock file or two in the temporary folder
    (2,053 after a fuzz). Removing them must not let two holders in at once: a lock file's holder
    removes it, a waiter that locked the removed file takes the new one."""
    import threading
    import time

    from rover_cosim.common import locks

    (tmp_path / "tmp").mkdir()
    (tmp_path / "run").mkdir(mode=0o700)
    monkeypatch.setenv("TMPDIR", str(tmp_path / "tmp"))
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path / "run"))
    monkeypatch.setattr(tempfile, "tempdir", None)
    assert locks.lock_folder() == tmp_path / "run" / "rover-cosim-locks"
    assert cli.main([*FIG3, "--out", str(tmp_path / "out")]) == 0
    assert not [p.name for p in (tmp_path / "tmp").iterdir()]
    assert not [p.name for p in (tmp_path / "run" / "rover-cosim-locks").iterdir()]
    counter = tmp_path / "counter"
    counter.write_text("0")

    def add_one() -> None:
        for _ in range(20):
            with locks.folder_locks([tmp_path / "shared"]):
                value = int(counter.read_text())
                time.sleep(0.001)  # another holder would read the same value meanwhile
                counter.write_text(str(value + 1))

    threads = [threading.Thread(target=add_one) for _ in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert counter.read_text() == "80"
    assert not [p.name for p in (tmp_path / "tmp").iterdir()]
    assert not [p.name for p in (tmp_path / "run" / "rover-cosim-locks").iterdir()]


def _private_runtime(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    (tmp_path / "run").mkdir(mode=0o700)
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path / "run"))
    return tmp_path / "run" / "rover-cosim-locks"


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX file modes and links")
def test_lock_files_live_in_a_private_folder_and_follow_no_link(tmp_path, monkeypatch):
    """Before: lock files had predictable names in the shared temporary folder and were opened
    following links, so a planted link made a run write "PID n (rover-cosim run)" into another
    file. Now the folder is the user's alone (0700, a real folder) and a link there is not followed."""
    from rover_cosim.common import locks

    folder = _private_runtime(tmp_path, monkeypatch)
    assert locks.lock_folder() == folder and folder.stat().st_mode & 0o777 == 0o700
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    target = tmp_path / "out.csv"
    lock = locks.lock_file(target, "busy")
    assert lock is not None and lock.parent == folder
    lock.symlink_to(victim)
    with locks.writing(target, "rover-cosim run"):
        pass
    assert victim.read_text() == "precious"
    lock.unlink()
    shared = tmp_path / "shared-run"   # a folder others may enter is not taken: the next candidate is
    shared.mkdir(mode=0o777)
    shared.chmod(0o777)
    (shared / "rover-cosim-locks").mkdir(mode=0o777)
    (shared / "rover-cosim-locks").chmod(0o777)
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(shared))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    assert locks.lock_folder() == tmp_path / "cache" / "rover-cosim" / "locks"
    odd = Path(os.fsdecode(b"\xff\xfe-not-utf8.csv"))  # a path that is not UTF-8 has a lock file too
    assert locks.lock_file(tmp_path / odd, "busy") is not None


@pytest.mark.skipif(sys.platform == "win32", reason="flock")
def test_stale_lock_files_are_removed_and_held_ones_kept(tmp_path, monkeypatch):
    from rover_cosim.common import locks

    folder = _private_runtime(tmp_path, monkeypatch)
    folder.mkdir(mode=0o700)
    stale, held = folder / "rover-cosim-busy-0123", folder / "rover-cosim-busy-4567"
    for path in (stale, held):
        path.write_text("PID 1 (rover-cosim run)")
        os.utime(path, (time.time() - 2 * locks.STALE_SECONDS,) * 2)
    with locks._held(held, wait=False):
        assert locks.remove_stale_locks() == [stale]
    assert not stale.exists()
