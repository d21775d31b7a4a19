"""The wheel contact's quadrature as vector code in the generated C (issue 49).

CasADi writes a Modelica function node by node, with a call of the C library per sine, cosine and
exp; the contact's quadrature (``contactResidual``, the sinkage solve's residual with the forces)
is most of a rover FMU's time. Where the generated code holds CasADi's function of
``contactResidual`` with ``lateralAtZero`` false (the one the sinkage solve calls), this module
renames it ``<name>_generic`` and puts a function of the old name in its place that calls
``runtime/contact.h``'s vector code (``rc_contact_forces``): every wheel the model describes
(grousers, slip-sinkage, a rut, a slip angle); the generic function only for arguments out of the
vector code's range (a NaN, a slip angle within 4 degrees of 90). The entry and exit angles,
tan(phi), the moduli at the slip angle, the sinkage exponent at the slip, the grousers'
engagement, Hegedus' factors, the residual's log and the sidewall's mobilisation are computed as
``contactForces``/``contactResidual`` compute them, with the same elementary functions
(``--elementary own`` renames them here too); only the quadrature's sines, cosines, exps and the
power law's logs are contact.h's. The derivatives (Jacobians, the sinkage's implicit derivative)
stay CasADi's. Measured: tests/test_contact_kernel.py, benchmarks/bench_contact_limit.py.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

HEADER = "contact.h"
#: contact.h's RC_CONTACT_MAX_NODES
MAX_NODES = 32

#: CasADi's comment before each function it writes, then the function's first line.
_FUNCTION = re.compile(r"/\* contactResidual_(\d+)_0:\(([^)]*)\)->\(([^)]*)\) \*/\n"
                       r"static int (\w+)\(const casadi_real\*\* arg, casadi_real\*\* res, casadi_int\* iw, "
                       r"casadi_real\* w, int mem\) \{\n")

#: The inputs and outputs the replacement reads and writes, by contactResidual's names.
INPUTS = ("logSinkage", "W", "slip", "soil_c", "soil_phi", "soil_kc", "soil_kphi", "soil_n", "soil_kx", "soil_a0",
          "soil_a1", "soil_lam", "soil_kxBeta", "soil_ky", "soil_kyBeta", "soil_rho", "soil_gravity", "soil_xc",
          "soil_nSlip", "wheel_r", "wheel_b", "wheel_grouserHeight", "wheel_grouserCount", "WMin", "slipAngle",
          "rutDepth")
OUTPUTS = ("residual", "h", "Fx", "Fz", "Tx", "Fy", "FySidewall")


def gauss_legendre(n: int, i: int) -> tuple[float, float]:
    """Node i (1..n) of the n-point Gauss-Legendre rule on [0, 1] and its weight, computed as the
    Modelica function ``gaussLegendre`` computes them (Tricomi's estimate, 10 Newton steps)."""
    x = math.cos(3.141592653589793 * (n + 1 - i - 0.25) / (n + 0.5))
    dp = 1.0
    for _ in range(10):
        p0, p1 = 1.0, x
        for m in range(2, n + 1):
            p0, p1 = p1, ((2 * m - 1) * x * p1 - (m - 1) * p0) / m
        dp = n * (x * p1 - p0) / (x * x - 1)
        x = x - p1 / dp
    return (1 + x) / 2, 1 / ((1 - x * x) * dp * dp)


def _replacement(name: str, nodes: int, inputs: list[str], outputs: list[str]) -> str:
    index = {n: i for i, n in enumerate(inputs)}
    slot = {n: i for i, n in enumerate(outputs)}
    pairs = [gauss_legendre(nodes, i) for i in range(1, nodes + 1)]
    u = ", ".join(f"{p[0].hex()}" for p in pairs)
    w = ", ".join(f"{p[1].hex()}" for p in pairs)

    def v(key: str) -> str:
        return f"in[{index[key]}]"

    writes = "\n".join(f"  if (res[{slot[key]}]) res[{slot[key]}][0] = {value};" for key, value in (
        ("residual", "residual"), ("h", "h"), ("Fx", "forces[0]"), ("Fz", "forces[1]"), ("Tx", "forces[2]"),
        ("Fy", "fy"), ("FySidewall", "sidewall")))
    return f"""
/* contactResidual_{nodes}_0 with the quadrature of runtime/contact.h (fmubuild/contact.py); CasADi's
 * {name}_generic for arguments out of its range */
static int {name}(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem) {{
  static const casadi_real u[{nodes}] = {{{u}}};
  static const casadi_real weights[{nodes}] = {{{w}}};
  casadi_real in[{len(inputs)}], forces[3];
  int k;
  for (k = 0; k < {len(inputs)}; k++) in[k] = arg[k] ? arg[k][0] : 0;
  if (!({v("logSinkage")} <= 700) || !({v("slipAngle")} > -1.5 && {v("slipAngle")} < 1.5))
    return {name}_generic(arg, res, iw, w, mem);
  {{
  casadi_real r = {v("wheel_r")}, b = {v("wheel_b")}, slip = {v("slip")};
  casadi_real phi = {v("soil_phi")}, beta = {v("slipAngle")};
  casadi_real gh = {v("wheel_grouserHeight")}, nSlip = {v("soil_nSlip")};
  casadi_real h = exp({v("logSinkage")}), hc = h > 0.0 ? (h < r ? h : r) : 0.0;
  casadi_real thetaF = acos(1 - hc/r), thetaR = -acos(1 - {v("soil_lam")}*hc/r);
  casadi_real load = {v("W")} > {v("WMin")} ? {v("W")} : {v("WMin")};
  casadi_real ky = {v("soil_ky")} + {v("soil_kyBeta")}*fabs(beta);
  casadi_real tanBeta = tan(beta), engagement, sumFy = 0, sumPile = 0, sidewall, fy, residual;
  RcContact contact;
  RcLateral lateral;
  contact.c = {v("soil_c")};
  contact.tanPhi = tan(phi);
  contact.kc = {v("soil_kc")};
  contact.kphi = {v("soil_kphi")};
  contact.kx = {v("soil_kx")} + {v("soil_kxBeta")}*fabs(beta);
  contact.a0 = {v("soil_a0")};
  contact.a1 = {v("soil_a1")};
  contact.exponent = {v("soil_n")} + nSlip*fabs(slip);
  contact.product = contact.exponent == 1 && nSlip == 0;
  contact.r = r;
  contact.b = b;
  engagement = {v("wheel_grouserCount")}*(thetaF - thetaR)/(2*3.141592653589793);
  engagement = engagement < 1.0 ? engagement : 1.0;
  contact.radius = r + engagement*gh;
  contact.ratio = contact.radius/r;
  contact.scaleForce = contact.ratio*(1 + 2*engagement*gh/b);
  contact.rutOverR = {v("rutDepth")}/r;
  if (tanBeta != 0) {{  /* the lateral terms, as contactForces computes them only then */
    casadi_real xc = {v("soil_xc")} > 0 ? {v("soil_xc")} : 0.7853981633974483 - phi/2, tanXc = tan(xc);
    lateral.tanBeta = tanBeta;
    lateral.ky = ky;
    lateral.d1 = 1/tanXc + tan(xc + phi);
    lateral.d2 = 1/tanXc + contact.tanPhi/(tanXc*tanXc);
    lateral.rho = {v("soil_rho")};
    lateral.gravity = {v("soil_gravity")};
  }}
  rc_contact_forces(&contact, thetaF, thetaR, slip, {nodes}, u, weights, tanBeta != 0 ? &lateral : 0, forces);
  if (tanBeta != 0) {{
    sumFy = lateral.sumFy;
    sumPile = lateral.sumPile;
  }}
  residual = forces[1] > 0 ? log(forces[1]/load) : -1e3;
  sidewall = -((beta >= 0 ? 1 - exp(-r*(1 - slip)*(thetaF - thetaR)*tanBeta/ky)
                : exp(r*(1 - slip)*(thetaF - thetaR)*tanBeta/ky) - 1)*sumPile);
  fy = sidewall - r*b*sumFy;
{writes}
  }}
  (void)iw; (void)w; (void)mem;
  return 0;
}}
"""


@dataclass(frozen=True)
class ContactFunction:
    """CasADi's function of a ``contactResidual`` with ``lateralAtZero`` false in generated C."""

    name: str           # its C name (casadi_f5, ...); the generic one becomes <name>_generic
    nodes: int          # contactForces' nNodes
    inputs: list[str]   # contactResidual's inputs, in CasADi's order (records flattened)
    outputs: list[str]
    start: int          # where its comment starts in the code
    body: int           # where its body starts
    end: int            # just after its closing brace


def contact_functions(code: str) -> list[ContactFunction]:
    """The functions of CasADi's C ``code`` that use_contact_kernel replaces."""
    found = []
    for match in _FUNCTION.finditer(code):
        inputs, outputs = match.group(2).split(","), match.group(3).split(",")
        nodes = int(match.group(1))
        if set(INPUTS) - set(inputs) or set(OUTPUTS) - set(outputs) or nodes > MAX_NODES:
            continue  # another signature than this module knows: CasADi's code as it is
        found.append(ContactFunction(match.group(4), nodes, inputs, outputs, match.start(), match.end(),
                                     code.index("\n}\n", match.end()) + 3))
    return found


def use_contact_kernel(code: str) -> str:
    """``code`` (CasADi's C) with each ``contactResidual`` function (``lateralAtZero`` false) calling
    contact.h's vector code for the wheels it covers (see the module's text), and contact.h
    included; unchanged where there is none."""
    pieces = []
    at = 0
    for function in contact_functions(code):
        first = code[function.start:function.body]
        pieces += [code[at:function.start], first.replace(f"static int {function.name}(",
                                                          f"static int {function.name}_generic("),
                   code[function.body:function.end],
                   _replacement(function.name, function.nodes, function.inputs, function.outputs)]
        at = function.end
    if not pieces:
        return code
    pieces.append(code[at:])
    return "".join(pieces).replace("#include <math.h>\n", f'#include <math.h>\n#include "{HEADER}"\n', 1)
