"""Unpacking FMUs and SSP archives without trusting them (issue 45): the bytes written count
against one limit per process, nested archives included (a small FMU that unpacks to gigabytes,
an FMU inside an SSP archive); an entry outside the folder or a link is refused; each refusal is
a message naming the archive, and `rover-cosim run` exits 1 without a traceback."""

from __future__ import annotations

import shutil
import zipfile
from pathlib import Path

import pytest
from c_fmu import built_or_skip
from misbehave_fmu import build_misbehave

from rover_cosim.cli import main
from rover_cosim.orchestrator import archives
from rover_cosim.orchestrator.archives import UnpackError, unpack_archive


@pytest.fixture(scope="module")
def misbehave(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return built_or_skip(build_misbehave(tmp_path_factory.mktemp("misbehave")))


def _bomb(fmu: Path, folder: Path, megabytes: int) -> Path:
    """``fmu`` with a resource of ``megabytes`` MB of zeros (a few kB compressed)."""
    bomb = folder / "Misbehave.fmu"
    shutil.copy(fmu, bomb)
    with zipfile.ZipFile(bomb, "a", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("resources/zeros.bin", bytes(megabytes << 20))
    return bomb


def test_an_fmu_that_unpacks_beyond_the_limit_is_refused_with_a_message(misbehave, tmp_path, monkeypatch, capsys):
    bomb = _bomb(misbehave, tmp_path, 64)
    assert bomb.stat().st_size < 1 << 20
    monkeypatch.setenv(archives.LIMIT_VARIABLE, str(16 << 20))
    assert main(["run", str(bomb), "-q", "-o", str(tmp_path / "out.csv")]) == 1
    said = capsys.readouterr().err
    assert "Misbehave.fmu: unpacking it would take 67" in said and "more than the limit of 16777216 bytes" in said
    assert archives.LIMIT_VARIABLE in said and "Traceback" not in said
    assert not (tmp_path / "out.csv").exists()


def test_the_limit_counts_every_archive_the_process_unpacks(tmp_path, monkeypatch):
    monkeypatch.setattr(archives, "_BUDGET", archives._Budget())
    monkeypatch.setenv(archives.LIMIT_VARIABLE, str(5 << 20))
    one = tmp_path / "one.zip"
    with zipfile.ZipFile(one, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("a.bin", bytes(3 << 20))
    written = unpack_archive(one, tmp_path / "first")
    assert written == 3 << 20
    with pytest.raises(UnpackError, match="more than 5242880 bytes in all"):
        unpack_archive(one, tmp_path / "second")  # 6 MB together: an FMU inside an archive counts with it
    archives.release(written)  # the first folder removed: room again
    assert unpack_archive(one, tmp_path / "third") == 3 << 20
    with pytest.raises(UnpackError, match="more than the limit of 1048576 bytes"):
        unpack_archive(one, tmp_path / "fourth", limit=1 << 20)  # an archive's own limit (SSP)


@pytest.mark.parametrize(("name", "said"), [("../escape.txt", "lies outside the archive's folder"),
                                            ("/abs.txt", "lies outside the archive's folder")])
def test_an_entry_outside_the_folder_is_refused(tmp_path, name, said):
    archive_path = tmp_path / "evil.fmu"
    with zipfile.ZipFile(archive_path, "w") as archive:
        archive.writestr(name, "x")
    with pytest.raises(UnpackError, match=said):
        unpack_archive(archive_path, tmp_path / "into")
    assert not (tmp_path / "escape.txt").exists()


def test_a_link_and_a_damaged_archive_are_refused(tmp_path):
    linked = tmp_path / "link.fmu"
    with zipfile.ZipFile(linked, "w") as archive:
        info = zipfile.ZipInfo("resources/passwd")
        info.external_attr = (0o120777 << 16)
        archive.writestr(info, "/etc/passwd")
    with pytest.raises(UnpackError, match="is a symbolic link"):
        unpack_archive(linked, tmp_path / "into")
    damaged = tmp_path / "damaged.fmu"
    damaged.write_bytes(b"PK\x03\x04 not really")
    with pytest.raises(UnpackError, match="not a readable zip archive"):
        unpack_archive(damaged, tmp_path / "into2")
