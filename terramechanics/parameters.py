"""Wheel and soil parameters of the terramechanics wheel model (paper Table 2).

These dataclasses are the single Python place for the wheel and soil numbers; the Modelica
records in ``modelica/`` mirror the same field names. All values are SI: lengths in m,
stresses in Pa, angles in rad.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, fields

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


def _check(name: str, value: object, ok: bool, expected: str) -> None:
    """Raise ValueError naming the field, its value and the accepted range unless ``ok``."""
    if not ok:
        raise ValueError(f"{name}={value!r} is not physical: expected {expected}")


def _check_finite(obj: object) -> None:
    """Every field a finite real number, stored as a Python float (numpy scalars accepted)."""
    for f in fields(obj):  # type: ignore[arg-type]
        value = getattr(obj, f.name)
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise TypeError(f"{f.name}={value!r}: expected a real number")
        value = float(value)
        _check(f.name, value, math.isfinite(value), "a finite number")
        object.__setattr__(obj, f.name, value)


@dataclass(frozen=True)
class Wheel:
    """Rigid wheel geometry and inertia.

    Attributes:
        r: wheel radius [m] (Table 2: 0.355 m).
        b: wheel width, "tread" in Table 2 [m] (0.175 m).
        J: wheel polar moment of inertia about its axle [kg·m²]. Not given in the paper;
            0.5 kg·m² is a uniform 8 kg disc of radius 0.355 m (J = m r² / 2), the order of a
            wheel rim of an ATHLETE-class rover. It only matters for wheel spin dynamics.
        grouser_height: height of the grousers above the rim [m] (0: a smooth wheel, the paper's).
        grouser_count: number of grousers around the rim [1], a whole number (0: smooth).
            See :mod:`terramechanics.grousers` for the model; with either at 0 every result is
            the smooth wheel's, bit for bit.
    """

    r: float = 0.355
    b: float = 0.175
    J: float = 0.5
    grouser_height: float = 0.0
    grouser_count: float = 0.0

    def __post_init__(self) -> None:
        _check_finite(self)
        _check("r", self.r, self.r > 0, "r > 0 m")
        _check("b", self.b, self.b > 0, "b > 0 m")
        _check("J", self.J, self.J > 0, "J > 0 kg·m²")
        _check("grouser_height", self.grouser_height, 0 <= self.grouser_height <= 0.5 * self.r,
               f"0 <= grouser_height <= r/2 = {0.5 * self.r!r} m")
        _check("grouser_count", self.grouser_count,
               0 <= self.grouser_count <= 360 and self.grouser_count == int(self.grouser_count),
               "a whole number of grousers in [0, 360]")

    @property
    def grousered(self) -> bool:
        """True for a wheel with grousers (height and count both above 0)."""
        return self.grouser_height > 0 and self.grouser_count > 0


#: The SI unit of every Soil and Wheel field (angles in rad; the library's files may give them in
#: degrees under ``phi_deg``, ``xc_deg``).
UNITS = {"c": "Pa", "phi": "rad", "kc": "N/m^(n+1)", "kphi": "N/m^(n+2)", "n": "1", "kx": "m", "a0": "1", "a1": "1",
         "lam": "1", "kx_beta": "m/rad", "ky": "m", "ky_beta": "m/rad", "rho": "kg/m^3", "gravity": "m/s^2",
         "xc": "rad", "n_slip": "1", "r": "m", "b": "m", "J": "kg.m^2", "grouser_height": "m", "grouser_count": "1"}

#: The closed range [min, max] (SI; None: unbounded) of every Soil and Wheel field: the FMUs'
#: min/max (the Modelica records declare them, tests/test_parameters.py keeps the two equal), and
#: what Soil and Wheel accept (where a bound is strict, e.g. 0 < phi, they also refuse the end).
RANGES: dict[str, tuple[float | None, float | None]] = {
    "c": (0.0, None), "phi": (0.0, math.pi / 2), "kc": (0.0, None), "kphi": (0.0, None), "n": (0.0, None),
    "kx": (0.0, None), "a0": (0.0, 1.0), "a1": (0.0, 1.0), "lam": (0.0, 1.0), "kx_beta": (0.0, None),
    "ky": (0.0, None), "ky_beta": (0.0, None), "rho": (0.0, None), "gravity": (0.0, None),
    "xc": (0.0, math.pi / 2), "n_slip": (0.0, None), "r": (0.0, None), "b": (0.0, None), "J": (0.0, None),
    "grouser_height": (0.0, None), "grouser_count": (0.0, 360.0)}

#: The value of ``Soil.xc`` that stands for "from φ": 45° - φ/2 (a NaN, replaced on construction).
XC_FROM_PHI = float("nan")


def xc_from_phi(phi: float) -> float:
    """Hegedus's destructive angle X_c = 45° - φ/2 [rad] of a soil of friction angle ``phi`` [rad]
    (as Ishigami et al. 2007 use it): the one definition, for the library, the jobs and the records."""
    return math.radians(45.0) - float(phi) / 2


@dataclass(frozen=True)
class Soil:
    """Soil parameters of the Bekker/Wong-Reece/Ishigami wheel-soil model (Eqs. 3-10).

    Attributes:
        c: cohesion stress [Pa] (Table 2: 0.80 kPa).
        phi: internal friction angle [rad] (Table 2: 37.2 deg); use ``Soil.from_degrees``
            to give it in degrees.
        kc: cohesive pressure-sinkage modulus [N/m^(n+1)] (1.37e3).
        kphi: frictional pressure-sinkage modulus [N/m^(n+2)] (8.14e5).
        n: sinkage exponent [-] (1.0).
        kx: shear deformation modulus in x [m] (0.036 m).
        a0: constant of the maximum-stress angle, Eq. (3) [-] (0.4).
        a1: slip coefficient of the maximum-stress angle, Eq. (3) [-] (0.15).
        lam: wheel sinkage ratio λ of the exit angle, Eq. (2) [-] (0.90).
        kx_beta: growth of kx with the slip angle [m/rad]: kx = kx + kx_beta |β| (Ishigami et al.
            2007: kx = 0.043 |β| + 0.036 m; the paper's kx is the β = 0 case).
        ky: lateral shear deformation modulus at β = 0 [m] (Ishigami et al. 2007: 0.013 m).
        ky_beta: growth of ky with the slip angle [m/rad] (0.020: ky = 0.020 |β| + 0.013 m).
        rho: dry density of the soil [kg/m³] (Ishigami et al. 2007: 1.6e3), for the sidewall.
        gravity: gravity acting on the soil [m/s²] (lunar, 1.62); rho·gravity is its weight density.
        xc: destructive angle of the soil piled against the wheel's side [rad]; left out (or
            :data:`XC_FROM_PHI`), Hegedus's 45° - φ/2, from the soil's own φ (26.4° for Table 2's
            37.2°). ``dataclasses.replace(soil, phi=...)`` keeps the xc it had; ``library.vary``
            and a soil table without xc derive it anew.
        n_slip: slip-sinkage: growth of the sinkage exponent with the slip ratio [1], n + n_slip |κ|
            (Ding, Gao, Deng et al., J. Terramechanics 48, 2011: n = n0 + n1 s, fitted on their
            single-wheel tests). 0 (default): the paper's soil, whose sinkage exponent does not
            depend on slip.

    The accepted ranges keep the contact patch well defined for every slip in [-1, 1]:
    0 < a0 - a1 and a0 + a1 < 1 put the maximum-stress angle strictly between the exit and
    entry angles.
    """

    c: float = 800.0
    phi: float = math.radians(37.2)
    kc: float = 1.37e3
    kphi: float = 8.14e5
    n: float = 1.0
    kx: float = 0.036
    a0: float = 0.4
    a1: float = 0.15
    lam: float = 0.90
    kx_beta: float = 0.043
    ky: float = 0.013
    ky_beta: float = 0.020
    rho: float = 1.6e3
    gravity: float = 1.62
    xc: float = float("nan")  # XC_FROM_PHI: 45 deg - phi/2, set in __post_init__
    n_slip: float = 0.0

    def __post_init__(self) -> None:
        if isinstance(self.xc, float) and math.isnan(self.xc) and isinstance(self.phi, (int, float)):
            object.__setattr__(self, "xc", xc_from_phi(self.phi))
        _check_finite(self)
        _check("c", self.c, self.c >= 0, "c >= 0 Pa")
        _check("phi", self.phi, 0 < self.phi < math.pi / 2, "0 < phi < pi/2 rad")
        _check("kc", self.kc, self.kc >= 0, "kc >= 0 N/m^(n+1)")
        _check("kphi", self.kphi, self.kphi > 0, "kphi > 0 N/m^(n+2)")
        _check("n", self.n, self.n > 0, "n > 0")
        _check("kx", self.kx, self.kx > 0, "kx > 0 m")
        _check("a0", self.a0, 0 < self.a0 < 1, "0 < a0 < 1")
        _check("a1", self.a1, 0 <= self.a1 < self.a0 and self.a0 + self.a1 < 1,
               f"0 <= a1 < min(a0, 1 - a0) = {min(self.a0, 1 - self.a0)!r}")
        _check("lam", self.lam, 0 < self.lam <= 1, "0 < lam <= 1")
        _check("kx_beta", self.kx_beta, self.kx_beta >= 0, "kx_beta >= 0 m/rad")
        _check("ky", self.ky, self.ky > 0, "ky > 0 m")
        _check("ky_beta", self.ky_beta, self.ky_beta >= 0, "ky_beta >= 0 m/rad")
        _check("rho", self.rho, self.rho >= 0, "rho >= 0 kg/m³")
        _check("gravity", self.gravity, self.gravity >= 0, "gravity >= 0 m/s²")
        _check("xc", self.xc, 0 < self.xc < math.pi / 2, "0 < xc < pi/2 rad")
        _check("n_slip", self.n_slip, self.n_slip >= 0, "n_slip >= 0 (the sinkage exponent grows with slip)")

    @classmethod
    def from_degrees(cls, phi_deg: float, **others: float) -> Soil:
        """Soil with the friction angle given in degrees [deg]; other fields as keywords."""
        _check("phi_deg", phi_deg, isinstance(phi_deg, (int, float)) and 0 < phi_deg < 90,
               "0 < phi_deg < 90 deg")
        return cls(phi=math.radians(phi_deg), **others)

    @property
    def phi_deg(self) -> float:
        """Internal friction angle [deg]."""
        return math.degrees(self.phi)

    def shear_moduli(self, slip_angle: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """kx, ky [m] at the slip angle β [rad] (Ishigami et al. 2007): kx + kx_beta |β|, ky + ky_beta |β|."""
        size = np.abs(np.asarray(slip_angle, dtype=float))
        return self.kx + self.kx_beta * size, self.ky + self.ky_beta * size

    def blend(self, other: Soil, share: float) -> Soil:
        """The soil under a wheel where ``other`` has the share ``share`` [1] in [0, 1]: each
        parameter (1 - share) self + share other, as ``Components.RigidWheel`` blends ``soil`` and
        ``soilB`` by its ``soilShare`` (exact at 0 and 1). Every range is convex, so the blend of
        two valid soils is valid; xc, affine in phi when derived, blends as its derivation would."""
        if not isinstance(other, Soil):
            raise TypeError(f"other = {other!r}: expected a Soil")
        if not (isinstance(share, (int, float)) and 0.0 <= share <= 1.0):
            raise ValueError(f"share = {share!r}: expected a share of the other soil in [0, 1]")
        keep = 1.0 - share
        return Soil(**{f.name: keep * getattr(self, f.name) + share * getattr(other, f.name) for f in fields(self)})

    def sinkage_exponent(self, slip: ArrayLike) -> FloatArray:
        """The sinkage exponent at the slip ratio κ [-]: n + n_slip |κ| [1] (slip-sinkage, Ding et al.
        2011); n itself where n_slip is 0."""
        return self.n + self.n_slip * np.abs(np.asarray(slip, dtype=float))

    def bekker_modulus(self, b: float) -> float:
        """k = kc / b + kphi [N/m^(n+2)], the Bekker pressure-sinkage modulus for width b [m]."""
        return self.kc / b + self.kphi


@dataclass(frozen=True)
class Rover:
    """A rover's body and limbs: what the rover FMUs (Modelica ``RoverParameters``) take besides the
    soil and wheel. The wheels sit on two mirrored sides, ``len(x_limb)`` per side: wheels
    1..n on the left from front to rear, n+1..2n on the right at the same x. The gravity is the
    soil's (``Soil.gravity``): where the rover drives.

    Attributes:
        mass: total mass carried by the limbs [kg] (paper Sec. 4: 1570 kg).
        Iyy: pitch moment of inertia about the centre of gravity [kg·m²].
        Ixx: roll moment of inertia [kg·m²] (the steerable rover).
        Izz: yaw moment of inertia [kg·m²] (the steerable rover).
        h_cog: height of the centre of gravity above the wheel hubs [m].
        x_limb: longitudinal hub positions of one side, front to rear, from the centre of gravity [m].
        y_limb: lateral hub position of the left side, half the track width [m].
        k_limb: vertical stiffness of one limb [N/m].
        d_limb: vertical damping of one limb [N·s/m].
    """

    mass: float = 1570.0
    Iyy: float = 1120.0
    Ixx: float = 1120.0
    Izz: float = 1980.0
    h_cog: float = 1.0
    x_limb: tuple[float, ...] = (1.5, 0.0, -1.5)
    y_limb: float = 1.5
    k_limb: float = 2.0e4
    d_limb: float = 2.0e3

    def __post_init__(self) -> None:
        positions = self.x_limb
        if isinstance(positions, (str, bytes)) or not hasattr(positions, "__iter__"):
            raise TypeError(f"x_limb={positions!r}: expected a list of hub positions [m], front to rear")
        values: list[float] = []
        for value in positions:
            if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(float(value)):
                raise TypeError(f"x_limb={list(positions)!r}: expected finite numbers [m]")
            values.append(float(value))
        _check("x_limb", values, 1 <= len(values) <= 16, "1 to 16 hub positions per side [m]")
        _check("x_limb", values, all(a > b for a, b in zip(values, values[1:])),
               "positions from front to rear, strictly decreasing [m]")
        object.__setattr__(self, "x_limb", tuple(values))
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == "x_limb":
                continue
            if isinstance(value, bool) or not isinstance(value, numbers.Real):
                raise TypeError(f"{f.name}={value!r}: expected a real number")
            _check(f.name, value, math.isfinite(float(value)), "a finite number")
            object.__setattr__(self, f.name, float(value))
        _check("mass", self.mass, self.mass > 0, "mass > 0 kg")
        for name in ("Iyy", "Ixx", "Izz"):
            _check(name, getattr(self, name), getattr(self, name) > 0, f"{name} > 0 kg·m²")
        _check("h_cog", self.h_cog, self.h_cog >= 0, "h_cog >= 0 m (the centre of gravity at or above the hubs)")
        _check("y_limb", self.y_limb, self.y_limb > 0, "y_limb > 0 m")
        _check("k_limb", self.k_limb, self.k_limb > 0, "k_limb > 0 N/m")
        _check("d_limb", self.d_limb, self.d_limb >= 0, "d_limb >= 0 N·s/m")

    @property
    def axles(self) -> int:
        """Wheels per side."""
        return len(self.x_limb)

    @property
    def wheels(self) -> int:
        """Number of wheels: two sides of :attr:`axles`."""
        return 2 * len(self.x_limb)

    def static_wheel_load(self, gravity: float) -> float:
        """The mean load of a wheel at rest on level ground, M g / N [N], under ``gravity`` [m/s²]."""
        return self.mass * gravity / self.wheels


#: The unit of every Rover field.
ROVER_UNITS = {"mass": "kg", "Iyy": "kg.m^2", "Ixx": "kg.m^2", "Izz": "kg.m^2", "h_cog": "m", "x_limb": "m",
               "y_limb": "m", "k_limb": "N/m", "d_limb": "N.s/m"}
