"""The FMI 2.0 C runtime as a host sees it: warnings-clean C, and whatever a host passes (value
references out of range, NULL arrays, corrupted FMU states, calls in the wrong state) it answers
with fmi2Error and a message, never a crash. The calls run in a child process, so a crash fails
the test instead of taking pytest down."""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

# Runs in a child process: argv = FMU folder (extracted), model identifier, GUID.
PROBE = r'''
import ctypes, sys
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, defaultCallbacks

folder, identifier, guid = sys.argv[1:4]
messages = []
callbacks = fmi2CallbackFunctions()
callbacks.logger = fmi2CallbackLoggerTYPE(lambda env, name, status, category, text: messages.append(text.decode()))
callbacks.allocateMemory = defaultCallbacks.allocateMemory
callbacks.freeMemory = defaultCallbacks.freeMemory
fmu = FMU2Slave(guid=guid, unzipDirectory=folder, modelIdentifier=identifier, instanceName="probe")
fmu.instantiate(callbacks=callbacks)
c, lib = fmu.component, fmu.dll
U = ctypes.c_uint
D = ctypes.c_double

def status(name, *args):
    function = getattr(lib, name)
    function.restype = ctypes.c_int
    return function(c, *args)

def report(label, value):
    print(f"{label}={value} | {messages[-1] if messages else ''}", flush=True)

values = (D * 1)()
for vr in (0x7FFFFFFF, 0x80000000, 0xFFFFFFFF):
    report(f"GetReal {vr:#x}", status("fmi2GetReal", (U * 1)(vr), ctypes.c_size_t(1), values))
    report(f"SetReal {vr:#x}", status("fmi2SetReal", (U * 1)(vr), ctypes.c_size_t(1), (D * 1)(1.0)))
report("GetReal NULL", status("fmi2GetReal", None, ctypes.c_size_t(3), None))
report("SetReal NULL", status("fmi2SetReal", None, ctypes.c_size_t(2), None))
report("DoStep before init", status("fmi2DoStep", D(0.0), D(1e-3), ctypes.c_int(1)))
fmu.setupExperiment(startTime=0.0)
fmu.enterInitializationMode()
fmu.exitInitializationMode()
report("derivative NULL", status("fmi2GetDirectionalDerivative", None, ctypes.c_size_t(1), None, ctypes.c_size_t(1),
                                 None, None))
report("derivative 0xffffffff", status("fmi2GetDirectionalDerivative", (U * 1)(0), ctypes.c_size_t(1),
                                       (U * 1)(0xFFFFFFFF), ctypes.c_size_t(1), (D * 1)(1.0), (D * 1)()))
fmu.doStep(0.0, 1e-3)
state = fmu.getFMUstate()
blob = bytearray(fmu.serializeFMUstate(state))
for label, corrupt in (("one byte flipped", lambda b: b.__setitem__(len(b) // 2, b[len(b) // 2] ^ 0xFF)),
                       ("mode field", lambda b: b.__setitem__(16, 99)),
                       ("truncated", lambda b: b.__delitem__(slice(-8, None))),
                       ("zeros", lambda b: b.__setitem__(slice(None), bytes(len(b))))):
    bad = bytearray(blob)
    corrupt(bad)
    buffer = (ctypes.c_char * len(bad)).from_buffer(bad)
    handle = ctypes.c_void_p()
    report(f"DeSerialize {label}", status("fmi2DeSerializeFMUstate", buffer, ctypes.c_size_t(len(bad)),
                                          ctypes.byref(handle)))
good = fmu.deSerializeFMUstate(bytes(blob))
fmu.setFMUstate(good)
fmu.doStep(1e-3, 1e-3)
report("steps after the rejected states", 0)
fmu.freeFMUstate(good)
fmu.freeFMUstate(state)
fmu.terminate()
fmu.freeInstance()
print("END", flush=True)
'''


@pytest.fixture(scope="module")
def single_wheel_folder(fmus, tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("SingleWheel")
    with zipfile.ZipFile(fmus["SingleWheel"]) as archive:
        archive.extractall(folder)
    return folder


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not on PATH")
def test_runtime_compiles_without_warnings(single_wheel_folder):
    """The runtime (not CasADi's generated code) under -Wall -Wextra -pedantic -Werror."""
    sources = single_wheel_folder / "sources"
    command = ["gcc", "-std=c99", "-D_POSIX_C_SOURCE=200809L", "-Wall", "-Wextra", "-pedantic", "-Werror",
               "-fsyntax-only", "-I", str(sources),
               *[str(sources / f) for f in ("fmi2_api.c", "instance.c", "state.c", "cosim.c", "ode23s.c")]]
    result = subprocess.run(command, capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr


def test_generated_code_compiles_without_warnings(fmus, tmp_path):
    """The generated C of a wheel (CasADi's code after fmubuild.guards, and the model's data) under
    -Wall -Wextra -Werror, optimized so that gcc looks for values that may be read unset (the
    guarded branches declared theirs without a value: 1340 such warnings in SingleWheel; CasADi's
    fixed signature left 219 parameters unused)."""
    with zipfile.ZipFile(fmus["Wheel"]) as archive:
        archive.extractall(tmp_path)
    sources = tmp_path / "sources"
    for name in ("model_casadi.c", "model_data.c"):
        command = ["gcc", "-std=c99", "-D_POSIX_C_SOURCE=200809L", "-O1", "-Wall", "-Wextra", "-Werror", "-c",
                   "-I", str(sources), str(sources / name), "-o", str(tmp_path / (name + ".o"))]
        result = subprocess.run(command, capture_output=True, text=True, check=False)
        assert result.returncode == 0, result.stderr[-3000:]


def test_bad_calls_get_fmi2error_and_a_message_never_a_crash(single_wheel_folder):
    import fmpy

    md = fmpy.read_model_description(str(single_wheel_folder))
    result = subprocess.run([sys.executable, "-c", PROBE, str(single_wheel_folder), "SingleWheel", md.guid],
                            capture_output=True, text=True, timeout=120, check=False)
    assert result.returncode == 0, f"the host process died ({result.returncode}):\n{result.stdout}\n{result.stderr}"
    lines = dict(line.split("=", 1) for line in result.stdout.splitlines() if "=" in line)
    assert result.stdout.rstrip().endswith("END")
    for vr in ("0x7fffffff", "0x80000000", "0xffffffff"):
        for call in ("GetReal", "SetReal"):
            status, message = lines[f"{call} {vr}"].split(" | ")
            assert status == "3" and "no such Real variable" in message and str(int(vr, 16)) in message
    assert lines["GetReal NULL"].startswith("3 | ") and "NULL" in lines["GetReal NULL"]
    assert lines["SetReal NULL"].startswith("3 | ") and "NULL" in lines["SetReal NULL"]
    assert lines["DoStep before init"].startswith("3 | ") and "not allowed in the instantiated state" in \
        lines["DoStep before init"]
    assert lines["derivative NULL"].startswith("3 | ") and "NULL" in lines["derivative NULL"]
    assert lines["derivative 0xffffffff"].startswith("3 | ") and "expected a state or an input" in \
        lines["derivative 0xffffffff"]
    for label in ("one byte flipped", "mode field", "truncated", "zeros"):
        status, message = lines[f"DeSerialize {label}"].split(" | ")
        assert status == "3" and "not an FMU state" in message, (label, message)
    assert lines["steps after the rejected states"].startswith("0 | ")
