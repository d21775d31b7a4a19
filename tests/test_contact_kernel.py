"""The contact's quadrature as vector code in the FMUs (fmubuild.contact, runtime/contact.h): the
generated contactResidual calls the vector code, and it gives CasADi's node-by-node results to the
last digits over every soil of the library and the whole range of sinkage, load, slip and slip
angle, with and without grousers, slip-sinkage and a rut; the sinkage it returns bit for bit, and
the lateral outputs too where the slip angle is 0; arguments out of its range go to CasADi's code."""

from __future__ import annotations

import ctypes
import math
import shutil
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest

from rover_cosim.fmubuild import contact
from rover_cosim.fmubuild.artifact import CFLAGS
from rover_cosim.fmubuild.platforms import host_compiler
from rover_cosim.terramechanics import Soil, Wheel
from rover_cosim.terramechanics.library import build, entry, names

pytestmark = [pytest.mark.fmu,
              pytest.mark.skipif(shutil.which(host_compiler()) is None, reason="no C compiler on PATH")]

HARNESS = """
#include "model_casadi.c"
static casadi_real work[1 << 18];
static casadi_int iwork[1 << 14];
/* contactResidual at inputs[0..n_in) into outputs[0..n_out): the vector code's function or CasADi's */
int harness_contact(int generic, const double *inputs, int n_in, double *outputs, int n_out) {
    const casadi_real *arg[64];
    casadi_real *res[16];
    int k;
    for (k = 0; k < n_in; k++) arg[k] = &inputs[k];
    for (k = 0; k < n_out; k++) res[k] = &outputs[k];
    return generic ? %(name)s_generic(arg, res, iwork, work, 0) : %(name)s(arg, res, iwork, work, 0);
}
"""


class Contact:
    """Wheel.fmu's contactResidual, both codes, callable from Python."""

    def __init__(self, fmu: Path, folder: Path):
        with zipfile.ZipFile(fmu) as archive:
            archive.extractall(folder, [n for n in archive.namelist() if n.startswith("sources/")])
        sources = folder / "sources"
        functions = contact.contact_functions((sources / "model_casadi.c").read_text())
        assert len(functions) == 1, "Wheel.fmu has one contactResidual with lateralAtZero false"
        assert functions[0].name.endswith("_generic"), "CasADi's function, renamed by use_contact_kernel"
        self.inputs, self.outputs = functions[0].inputs, functions[0].outputs
        (sources / "harness.c").write_text(HARNESS % {"name": functions[0].name.removesuffix("_generic")})
        library = folder / "harness.so"
        command = [host_compiler(), *CFLAGS, "-fvisibility=default", "-I", str(sources), str(sources / "harness.c")]
        subprocess.run([*command, "-o", str(library), "-lm"], check=True)
        self.library = ctypes.CDLL(str(library))
        pointer = ctypes.POINTER(ctypes.c_double)
        self.library.harness_contact.argtypes = [ctypes.c_int, pointer, ctypes.c_int, pointer, ctypes.c_int]

    def __call__(self, generic: bool, values: dict[str, float]) -> dict[str, float]:
        given = np.array([values[name] for name in self.inputs], dtype=float)
        out = np.full(len(self.outputs), np.nan)
        pointer = ctypes.POINTER(ctypes.c_double)
        assert self.library.harness_contact(int(generic), given.ctypes.data_as(pointer), len(given),
                                            out.ctypes.data_as(pointer), len(out)) == 0
        return dict(zip(self.outputs, out.tolist()))


@pytest.fixture(scope="module")
def wheel_contact(fmus, tmp_path_factory) -> Contact:
    return Contact(fmus["Wheel"], tmp_path_factory.mktemp("contact"))


def _inputs(soil: Soil, wheel: Wheel, **changes: float) -> dict[str, float]:
    values = {"soil_c": soil.c, "soil_phi": soil.phi, "soil_kc": soil.kc, "soil_kphi": soil.kphi, "soil_n": soil.n,
              "soil_kx": soil.kx, "soil_a0": soil.a0, "soil_a1": soil.a1, "soil_lam": soil.lam,
              "soil_kxBeta": soil.kx_beta, "soil_ky": soil.ky, "soil_kyBeta": soil.ky_beta, "soil_rho": soil.rho,
              "soil_gravity": 9.81, "soil_xc": soil.xc, "soil_nSlip": soil.n_slip, "wheel_r": wheel.r,
              "wheel_b": wheel.b, "wheel_J": 1.0, "wheel_grouserHeight": wheel.grouser_height,
              "wheel_grouserCount": wheel.grouser_count, "WMin": 1e-3, "slipAngle": 0.0, "rutDepth": 0.0}
    return values | changes


def _soils() -> dict[str, Soil]:
    found = {name: build("soil", name, entry("soil", name)[1]) for name in names("soil")}
    return {name: soil for name, soil in found.items() if isinstance(soil, Soil)}


def test_the_vector_code_gives_casadis_forces_over_every_soil_and_the_whole_range(wheel_contact):
    """Forces within 3e-14 (measured 1.5e-14) of the largest force from 1 mm of sinkage on; below,
    cos(theta) - cos(thetaF) cancels (1 - theta^2/2 against 1 - thetaF^2/2), so that either code's
    last-place rounding of a cosine shows in the normal stress amplified: 1e-12 there (measured
    1.2e-13 at 1 um)."""
    wheel = Wheel()
    rng = np.random.default_rng(49)
    worst = {True: 0.0, False: 0.0}  # by sinkage >= 1 mm
    for soil in _soils().values():
        for case in range(1500):
            h = math.exp(rng.uniform(math.log(1e-6), math.log(1.2 * wheel.r)))  # past r: clamped
            beta = 0.0 if case % 2 else rng.uniform(-0.6, 0.6)
            effects = {}  # a quarter each: none, grousers, slip-sinkage, a rut
            if case % 4 == 1:
                effects = {"wheel_grouserHeight": rng.uniform(0.002, 0.02), "wheel_grouserCount": rng.uniform(8, 30)}
            elif case % 4 == 2:
                effects = {"soil_nSlip": rng.uniform(0.05, 0.5)}
            elif case % 4 == 3:
                effects = {"rutDepth": rng.uniform(0.0, 0.03)}
            values = _inputs(soil, wheel, logSinkage=math.log(h), W=rng.uniform(1.0, 2000.0), slip=rng.uniform(-1, 1),
                             slipAngle=beta, **effects)
            ours, casadi = wheel_contact(False, values), wheel_contact(True, values)
            keys = ("Fx", "Fz", "Tx", "Fy", "FySidewall")
            scale = max(*(abs(casadi[k]) for k in keys), abs(casadi["Tx"]) / wheel.r)
            difference = max(abs(ours[k] - casadi[k]) for k in keys if k != "Tx") / scale
            difference = max(difference, abs(ours["Tx"] - casadi["Tx"]) / wheel.r / scale)
            worst[h >= 1e-3] = max(worst[h >= 1e-3], difference)
            if abs(casadi["Fz"]) > 1e-10 * scale:  # log(Fz/W): Fz's relative difference
                allowed = 2 * difference * scale / abs(casadi["Fz"]) + 4e-16 * abs(casadi["residual"]) + 1e-15
                assert abs(ours["residual"] - casadi["residual"]) <= allowed, values
            for key in ("h", *(("Fy", "FySidewall") if beta == 0 else ())):  # bit for bit, a zero's sign too
                assert math.copysign(1.0, ours[key]) == math.copysign(1.0, casadi[key]) and ours[key] == casadi[key]
    print(f"largest difference of a force over the largest: {worst[True]:.1e} (h >= 1 mm), {worst[False]:.1e} below")
    assert worst[True] <= 3e-14 and worst[False] <= 1e-12, worst


@pytest.mark.parametrize("change", [{"slipAngle": 1.55}, {"slipAngle": -1.5}, {"logSinkage": float("nan")},
                                    {"slipAngle": float("nan")}, {"logSinkage": 800.0}],
                         ids=["slip-angle-near-90-deg", "minus-1.5-rad", "nan-sinkage", "nan-slip-angle",
                              "huge-log-sinkage"])
def test_arguments_out_of_its_range_go_to_casadis_code(wheel_contact, change):
    values = _inputs(Soil(), Wheel(), logSinkage=math.log(0.02), W=400.0, slip=0.3) | change
    ours, casadi = wheel_contact(False, values), wheel_contact(True, values)
    assert np.array_equal(np.array(list(ours.values())), np.array(list(casadi.values())), equal_nan=True)


def test_code_without_the_solves_contact_is_left_as_it_is():
    code = "#include <math.h>\n/* contactResidual_10_1:(logSinkage)->(residual) */\nstatic int f(void) {\n}\n"
    assert contact.use_contact_kernel(code) == code
    assert contact.gauss_legendre(10, 10)[0] == pytest.approx(0.9869532642585859, abs=1e-15)
    assert sum(contact.gauss_legendre(10, i)[1] for i in range(1, 11)) == pytest.approx(1.0, abs=1e-15)
