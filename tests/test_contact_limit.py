"""The contact-limit benchmark measures the physics it claims to (benchmarks/contact_limit.c): both
of its codes, node by node with the C library and the FMUs' vector code (runtime/contact.h), give
the numpy reference's forces with the same nodes (driving, where both integrate the same two
pieces), on a soil with n = 1 (the product) and one with n != 1 (exp(n log x)), and with the FMUs'
flags gcc makes vector code of contact.h's elementary functions."""

from __future__ import annotations

import importlib.util
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rover_cosim.fmubuild.platforms import host_compiler
from rover_cosim.terramechanics import Soil, Wheel, contact_forces

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.skipif(shutil.which(host_compiler()) is None, reason="no C compiler on PATH")


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("bench_contact_limit", ROOT / "benchmarks" / "bench_contact_limit.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def kernel(bench, tmp_path_factory):
    return bench.compile_kernel(tmp_path_factory.mktemp("kernel"), "baseline", ())


@pytest.mark.parametrize("soil", [Soil(), Soil(n=0.7, kc=5.27e3, kphi=1.52e6, c=1.7e3, phi=0.5)],
                         ids=["n=1", "n=0.7"])
def test_both_codes_give_the_numpy_forces(bench, kernel, soil):
    wheel = Wheel()
    u, w = bench.gauss_legendre_unit()
    h, slip = bench.cases(soil, wheel)
    assert len(h) > 20
    driving = (slip >= 0) & (h <= wheel.r / 2)
    reference = contact_forces(h[driving], slip[driving], wheel, soil, bench.NODES)
    expected = np.stack([reference.Fx, reference.Fz, reference.Tx], axis=1)
    scale = np.abs(expected[:, 1]).max()
    p = bench.parameters(soil, wheel)
    for vector in (False, True):
        got = bench.forces(kernel, vector, p, h[driving], slip[driving], u, w)
        assert np.abs(got - expected).max() <= 1e-12 * scale, vector
    # braking too: the two codes agree with each other (the reference splits the patch there)
    scalar = bench.forces(kernel, False, p, h, slip, u, w)
    vector = bench.forces(kernel, True, p, h, slip, u, w)
    assert np.abs(vector - scalar).max() <= 1e-12 * scale


def test_the_vector_code_is_vectorised(bench, tmp_path):
    version = subprocess.run([host_compiler(), "--version"], capture_output=True, text=True, check=False).stdout
    if "Free Software Foundation" not in version:
        pytest.skip(f"{host_compiler()} is not gcc: -fopt-info is gcc's report of what it vectorised")
    done = subprocess.run([host_compiler(), *bench.BASE_FLAGS, "-fopt-info-vec-optimized", "-I", str(bench.RUNTIME),
                           "-c", str(bench.KERNEL), "-o", str(tmp_path / "k.o")], capture_output=True, text=True,
                          check=True)
    vectorised = {line.split("contact.h:")[1].split(":")[0] for line in done.stderr.splitlines()
                  if "contact.h:" in line and "loop vectorized" in line}
    source = (bench.RUNTIME / "contact.h").read_text().splitlines()
    loops = {name: next(i for i, line in enumerate(source, 1) if line.startswith(f"static void {name}("))
             for name in ("rc_sincos_array", "rc_exp_array", "rc_log_array")}
    for name, line in loops.items():  # each function's loop is the line after its signature
        assert str(line + 1) in vectorised, name
