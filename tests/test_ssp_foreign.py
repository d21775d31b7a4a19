"""SSP archives of any producer, on the test FMU of our own (tests/fmus/typed.c): an archive
without our annotation (its step from the FMUs' DefaultExperiment or the command line;
connections and parameter values of every type, an enumeration by item name, inline parameter
values), our export with typed connectors and parameter values, and what an archive may not do:
name an unregistered Python factory, point outside itself, exceed the size limit, carry a
nested system; --step and --stop-time checked as on a system file."""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np
import pytest

from rover_cosim.cli import main
from rover_cosim.orchestrator import SystemBuilder, run
from rover_cosim.orchestrator.model import System, SystemFileError
from rover_cosim.orchestrator.ssp import SspError, export_ssp, load_ssp, validate_ssd

SSD_HEAD = ('<?xml version="1.0" encoding="UTF-8"?>\n<ssd:SystemStructureDescription '
            'xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" '
            'xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" '
            'xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="1.0" name="foreign">')



def _component(name: str, source: str, inline: str = "") -> str:
    connectors = ('<ssd:Connectors><ssd:Connector name="u" kind="input"><ssc:Real/></ssd:Connector>'
                  '<ssd:Connector name="y" kind="output"><ssc:Real/></ssd:Connector>'
                  '<ssd:Connector name="k" kind="input"><ssc:Integer/></ssd:Connector>'
                  '<ssd:Connector name="k2" kind="output"><ssc:Integer/></ssd:Connector>'
                  '<ssd:Connector name="b" kind="input"><ssc:Boolean/></ssd:Connector>'
                  '<ssd:Connector name="notb" kind="output"><ssc:Boolean/></ssd:Connector>'
                  '<ssd:Connector name="s" kind="input"><ssc:String/></ssd:Connector>'
                  '<ssd:Connector name="sout" kind="output"><ssc:String/></ssd:Connector></ssd:Connectors>')
    return (f'<ssd:Component name="{name}" type="application/x-fmu-sharedlibrary" source="{source}">'
            f'{connectors}{inline}</ssd:Component>')


def _foreign(typed: Path, folder: Path, *, source: str = "resources/Typed.fmu", extra_entries: dict | None = None,
             elements: str | None = None) -> Path:
    """A foreign archive: two Typed components, a -> b on every type, a's values from an .ssv
    file (every type), b's inline; a DefaultExperiment with a stop time only; no annotation."""
    ssv = ('<?xml version="1.0" encoding="UTF-8"?>\n<ssv:ParameterSet '
           'xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="1.0" name="a">'
           '<ssv:Parameters>'
           '<ssv:Parameter name="gain"><ssv:Real value="3.0"/></ssv:Parameter>'
           '<ssv:Parameter name="u"><ssv:Real value="0.5"/></ssv:Parameter>'
           '<ssv:Parameter name="k"><ssv:Integer value="7"/></ssv:Parameter>'
           '<ssv:Parameter name="b"><ssv:Boolean value="true"/></ssv:Parameter>'
           '<ssv:Parameter name="label"><ssv:String value="A"/></ssv:Parameter>'
           '<ssv:Parameter name="s"><ssv:String value="x"/></ssv:Parameter>'
           '</ssv:Parameters></ssv:ParameterSet>')
    inline = ('<ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues>'
              '<ssv:ParameterSet version="1.0" name="b"><ssv:Parameters>'
              '<ssv:Parameter name="label"><ssv:String value="B"/></ssv:Parameter>'
              '</ssv:Parameters></ssv:ParameterSet></ssd:ParameterValues></ssd:ParameterBinding>'
              '</ssd:ParameterBindings>')
    bound = ('<ssd:ParameterBindings><ssd:ParameterBinding source="resources/a.ssv"/></ssd:ParameterBindings>')
    connections = "".join(f'<ssd:Connection startElement="a" startConnector="{out}" endElement="b" '
                          f'endConnector="{into}"/>' for out, into in
                          (("y", "u"), ("k2", "k"), ("notb", "b"), ("sout", "s")))
    elements = elements if elements is not None else _component("a", source, bound) + _component("b", source, inline)
    ssd = (f'{SSD_HEAD}<ssd:System name="top"><ssd:Elements>{elements}</ssd:Elements>'
           f'<ssd:Connections>{connections}</ssd:Connections></ssd:System>'
           '<ssd:DefaultExperiment startTime="0" stopTime="0.5"/></ssd:SystemStructureDescription>')
    archive = folder / "foreign.ssp"
    with zipfile.ZipFile(archive, "w") as zf:
        zf.writestr("SystemStructure.ssd", ssd)
        zf.writestr("resources/a.ssv", ssv)
        zf.write(typed, "resources/Typed.fmu")
        for name, data in (extra_entries or {}).items():
            zf.writestr(name, data)
    return archive


def test_a_foreign_archive_runs_with_the_fmus_default_step(typed, tmp_path):
    system = load_ssp(_foreign(typed, tmp_path), tmp_path / "unpacked")
    assert system.step == 0.1 and system.stop_time == 0.5 and "DefaultExperiment" in system.settings_from["step"]
    data = run(system).data
    assert len(data) == 6
    assert (data["b.y"] == 2.0 * 3.0 * 0.5).all()               # Real: a.y = 3 * 0.5 -> b.u, b.y = 2 * b.u
    assert data["b.k2"].tolist() == [7 + 2 * k for k in range(6)]  # Integer: a.k2 = 7 + n -> b.k, b.k2 = b.k + n
    assert (data["b.notb"]).all()                              # Boolean: not (not true)
    assert set(data["b.sout"]) == {"B:A:x"}                    # String, and an inline parameter value


def test_the_command_line_step_and_stop_time_apply_to_an_archive_and_are_checked(typed, tmp_path, capsys):
    archive = _foreign(typed, tmp_path)
    out = tmp_path / "run.csv"
    assert main(["run", str(archive), "--step", "0.05", "-o", str(out), "--quiet"]) == 0
    assert len(out.read_text().splitlines()) == 1 + 11
    for step, expected in (("0", "expected a communication step > 0 s"), ("-0.01", "expected a communication step"),
                           ("100", "longer than the run")):
        assert main(["run", str(archive), "--step", step, "-o", str(tmp_path / "x.csv"), "--quiet"]) == 2
        assert expected in capsys.readouterr().err
    assert not (tmp_path / "x.csv").exists()


def test_our_export_types_its_connectors_and_values_and_runs_back_the_same(typed, tmp_path):
    system = (SystemBuilder("mixed").simulation(stop_time=0.5, step=0.1)
              .add_fmu("a", typed, parameters={"label": "A", "stopAfter": 0}, start={"k": 3, "b": True, "s": "q"})
              .add_fmu("b", typed).connect("a.y", "b.u").connect("a.k2", "b.k").connect("a.notb", "b.b")
              .connect("a.sout", "b.s").build())
    archive = export_ssp(system, tmp_path / "mixed.ssp").path
    validate_ssd(archive)
    with zipfile.ZipFile(archive) as zf:
        ssd = zf.read("SystemStructure.ssd").decode()
        ssv = zf.read("resources/a.ssv").decode()
    compact = "".join(line.strip() for line in ssd.splitlines())
    assert '<ssd:Connector name="k" kind="input"><ssc:Integer/>' in compact
    assert '<ssc:Boolean/>' in ssd and '<ssc:String/>' in ssd
    assert '<ssv:Integer value="3"/>' in ssv and '<ssv:Boolean value="true"/>' in ssv and 'value="q"' in ssv
    again = run(load_ssp(archive, tmp_path / "unpacked")).data
    expected = run(system).data
    assert again.equals(expected)


def test_an_unregistered_python_factory_is_refused_before_anything_runs(typed, tmp_path):
    archive = export_ssp(SystemBuilder("s").simulation(stop_time=0.5, step=0.1).add_fmu("a", typed).build(),
                         tmp_path / "plain.ssp").path
    with zipfile.ZipFile(archive) as zf:
        files = {n: zf.read(n) for n in zf.namelist()}
    victim = tmp_path / "made-by-the-archive"
    ssd = files["SystemStructure.ssd"].decode().replace(
        '"blocks": []', f'"blocks": [{{"name": "evil", "type": "python", "factory": "os:makedirs", '
        f'"name_": "{victim}"}}]')
    assert '"factory": "os:makedirs"' in ssd
    files["SystemStructure.ssd"] = ssd.encode()
    with zipfile.ZipFile(tmp_path / "evil.ssp", "w") as zf:
        for name, data in files.items():
            zf.writestr(name, data)
    with pytest.raises(SystemFileError, match="'os:makedirs', which you have not allowed"):
        load_ssp(tmp_path / "evil.ssp", tmp_path / "unpacked")
    assert not victim.exists()


def test_sources_must_stay_inside_the_archive(typed, tmp_path):
    (tmp_path / "outside.fmu").write_bytes(typed.read_bytes())
    for source, message in (("../outside.fmu", "lies outside the archive"),
                            (str(tmp_path / "outside.fmu"), "expected a relative path inside the archive"),
                            ("file:///etc/passwd", "expected a relative path inside the archive"),
                            ("resources/missing.fmu", "is not in the archive")):
        folder = tmp_path / f"case{abs(hash(source))}"
        folder.mkdir()
        archive = _foreign(typed, folder, source=source)
        with pytest.raises(SspError, match=message):
            load_ssp(archive, folder / "unpacked")
    folder = tmp_path / "slip"
    folder.mkdir()
    with zipfile.ZipFile(folder / "slip.ssp", "w") as zf:
        zf.writestr("../../escaped.txt", "x")
        zf.writestr("SystemStructure.ssd", SSD_HEAD + "</ssd:SystemStructureDescription>")
    with pytest.raises(SspError, match="lies outside the archive's folder"):
        load_ssp(folder / "slip.ssp", folder / "unpacked")
    assert not (tmp_path / "escaped.txt").exists()


def test_an_archive_above_the_size_limit_is_refused(typed, tmp_path, monkeypatch):
    archive = _foreign(typed, tmp_path, extra_entries={"resources/padding.bin": b"\0" * 200_000})
    monkeypatch.setenv("ROVER_COSIM_SSP_MAX_BYTES", "100000")
    with pytest.raises(SspError, match="more than the limit of 100000 bytes"):
        load_ssp(archive, tmp_path / "unpacked")
    monkeypatch.setenv("ROVER_COSIM_SSP_MAX_BYTES", "lots")
    with pytest.raises(SspError, match="expected a whole number of bytes"):
        load_ssp(archive, tmp_path / "unpacked2")


def test_what_the_engine_does_not_run_is_named(typed, tmp_path):
    inner = _component("c", "resources/Typed.fmu")
    nested = f'<ssd:System name="inner"><ssd:Elements>{inner}</ssd:Elements></ssd:System>'
    archive = _foreign(typed, tmp_path, elements=_component("a", "resources/Typed.fmu") + nested)
    with pytest.raises(SspError, match=r"nested systems \(inner\) are not supported"):
        load_ssp(archive, tmp_path / "unpacked")


def _mixed_archive(typed: Path, folder: Path) -> tuple[System, Path]:
    """a -> b across Real, Integer and Boolean (what FMPy's and libcosim's SSP readers exchange),
    Jacobi; a's k and b given start values, exported as an SSP archive."""
    system = (SystemBuilder("mixed").simulation(stop_time=0.5, step=0.1, algorithm="jacobi")
              .add_fmu("a", typed, parameters={"gain": 3.0}, start={"u": 0.5, "k": 4, "b": True})
              .add_fmu("b", typed).connect("a.y", "b.u").connect("a.k2", "b.k").connect("a.notb", "b.b")
              .record("b.y", "b.k2", "b.notb").build())
    return system, export_ssp(system, folder / "mixed.ssp").path


def test_fmpy_runs_our_mixed_type_archive_to_our_values(typed, tmp_path):
    from fmpy.ssp.simulation import simulate_ssp

    from rover_cosim.orchestrator.ssp import fmpy_parameter_set

    system, archive = _mixed_archive(typed, tmp_path)
    ours = run(system).data
    theirs = simulate_ssp(str(archive), stop_time=0.5, step_size=0.1, parameter_set=fmpy_parameter_set(archive))
    # FMPy's simulate_ssp labels each row with the time at the start of the step it has just taken,
    # and starts the connections at 0 in its first step (no initial exchange): its row k is our row
    # k + 1, compared from its second row on
    for column in ("b.y", "b.k2", "b.notb"):
        got = theirs[[n for n in theirs.dtype.names if n.endswith(column)][0]]
        np.testing.assert_array_equal(np.asarray(got[1:], dtype=float), ours[column].to_numpy(float)[2:],
                                      err_msg=column)


def test_libcosim_runs_our_mixed_type_archive_to_our_values(typed, tmp_path):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    system, archive = _mixed_archive(typed, tmp_path)
    ours = run(system).data
    execution = CosimExecution.from_ssp_file(str(archive), step_size=round(0.1 * 1e9))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    index = {(i.name.decode() if isinstance(i.name, bytes) else i.name): i.index for i in execution.slave_infos()}
    got = []
    for _ in range(5):
        execution.step(1)
        got.append((observer.last_real_values(index["b"], [2])[0], observer.last_integer_values(index["b"], [2])[0],
                    observer.last_boolean_values(index["b"], [2])[0]))
    theirs = np.array(got, dtype=float)
    np.testing.assert_array_equal(theirs[:, 0], ours["b.y"].to_numpy()[1:])
    np.testing.assert_array_equal(theirs[:, 1], ours["b.k2"].to_numpy(float)[1:])
    np.testing.assert_array_equal(theirs[:, 2], ours["b.notb"].to_numpy(float)[1:])
