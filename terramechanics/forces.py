"""Contact forces of the rigid wheel on loose soil: Fz, Fx, Tx by Eqs. (11)-(13).

Quadrature. σ has a kink at θm, so [θr, θm] and [θm, θf] are integrated separately, each by
Gauss-Legendre on u in [0, 1] after the substitution

    front:  θ = θf - (θf - θm) u²,      rear:  θ = θr + (θm - θr) u²,

which clusters nodes at the two ends of the patch where σ goes to zero like (θf - θ)^n. For
n = 1 the integrands stay smooth (exponential convergence); for other n the substitution turns
the end-point singularity (θf - θ)^n into u^(2n+1), which Gauss-Legendre handles well. A side
effect used for speed: with the same nodes on both pieces, the rear normal stress of Eq. (6) at
node u equals the front stress of Eq. (5) at the same node, so σ is evaluated once.

Two refinements keep the error below 1e-6 over the whole domain (tests/test_forces.py):
- a skidding wheel (κ < 0) can shear the soil backwards over part of the patch; τx then has a
  kink where jx = 0, and the patch is split there as well (up to four pieces);
- a wheel sunk deeper than r/2 gets 1.5 times the nodes (its patch spans up to π rad).
Rows are processed in blocks so that the (rows, pieces, nodes) temporaries stay in cache.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from .checks import check_nodes, checked_array
from .grousers import grouser_engagement, shear_radius, side_shear_factor
from .kinematics import BoolArray, FloatArray, IndexArray, entry_angle, exit_angle, max_stress_angle
from .lateral import lateral_integrals
from .parameters import Soil, Wheel
from .stress import normal_stress, pressure_from_cosines, shear_displacement, shear_stress

#: Gauss-Legendre nodes per piece of the contact patch (front and rear; 1.5 times as many for
#: a wheel sunk deeper than r/2); see tests/test_forces.py for the measured error against a
#: 20 000-point reference.
DEFAULT_NODES = 12

#: Rows evaluated together, so that the (rows, nodes) temporaries fit in a CPU cache.
BLOCK_SIZE = 2048


class ContactForces(NamedTuple):
    """Wheel-soil contact forces, arrays of the broadcast shape of the inputs."""

    Fx: FloatArray  #: longitudinal force (drawbar pull) [N], Eq. (12)
    Fz: FloatArray  #: vertical force [N], Eq. (11)
    Tx: FloatArray  #: resistance torque about the axle [N·m], Eq. (13)
    Fy: FloatArray  #: lateral force [N] (Ishigami et al. 2007), opposing the hub's sideways sliding
    Fy_sidewall: FloatArray  #: the sidewall (bulldozing) part of Fy [N]


@lru_cache(maxsize=16)
def _unit_nodes(nodes: int) -> tuple[FloatArray, FloatArray]:
    """Gauss-Legendre nodes u and weights w on [0, 1]."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    u, weights = 0.5 * (x + 1.0), 0.5 * w
    u.flags.writeable = False
    weights.flags.writeable = False
    return u, weights


@lru_cache(maxsize=64)
def _piece_maps(clusters: tuple[str, ...], nodes: int) -> tuple[FloatArray, FloatArray]:
    """Node positions s and weights ds/du·w on [0, 1], shape (pieces, nodes), per piece.

    A piece [start, end] gets θ = start + (end - start) s, with s = u² where ``clusters`` says
    "start" (nodes crowd at the start) and s = 1 - u² where it says "end".
    """
    u, w = _unit_nodes(nodes)
    maps = {"start": (u * u, 2.0 * u * w), "end": (1.0 - u * u, 2.0 * u * w)}
    s = np.stack([maps[c][0] for c in clusters])
    ds = np.stack([maps[c][1] for c in clusters])
    s.flags.writeable = False
    ds.flags.writeable = False
    return s, ds


def _patch_nodes(breaks: FloatArray, clusters: tuple[str, ...], nodes: int) -> tuple[FloatArray, FloatArray]:
    """Quadrature angles θ and weights dθ, shape (M, pieces, nodes), for pieces between the
    rows of ``breaks`` (pieces + 1, M)."""
    s, ds = _piece_maps(clusters, nodes)
    start = breaks[:-1].T[:, :, None]
    length = (breaks[1:] - breaks[:-1]).T[:, :, None]
    return start + length * s, length * ds


def _shear_reversal_angles(theta_f: FloatArray, theta_r: FloatArray, slip: FloatArray,
                           wheel: Wheel) -> tuple[FloatArray, FloatArray]:
    """Angles inside the patch where jx (Eq. 10) changes sign; NaN where there is none.

    dj/dθ = r[(1 - κ) cos θ - 1]: for κ >= 0 it is never positive, so j >= 0 on the whole
    patch and there is no reversal. For κ < 0 it is positive for |θ| < θ* = acos(1/(1 - κ)),
    so j (zero at θf) has at most one root in (-θ*, θ*) and one in (θr, -θ*).
    """
    skid = slip < 0
    if not skid.any():  # a driving or rolling wheel: no reversal (the common case, without the search)
        none = np.full(slip.shape, np.nan)
        return none, none.copy()
    theta_star = np.arccos(1.0 / (1.0 - np.minimum(slip, 0.0)))
    # jx > 0 just behind θf only if θf > θ*; otherwise jx <= 0 on the whole patch.
    low1 = np.maximum(theta_r, -theta_star)
    j_low1 = shear_displacement(low1, theta_f, slip, wheel)
    j_star = shear_displacement(theta_star, theta_f, slip, wheel)
    j_rear = shear_displacement(theta_r, theta_f, slip, wheel)
    first = skid & (theta_f > theta_star) & (j_star > 0) & (j_low1 < 0)
    second = first & (theta_r < -theta_star) & (j_rear > 0)
    # Starting points from jx's parabola at its extrema ±θ*, where |d²j/dθ²| = r(1 - κ) sin θ*:
    # a root close to an extremum is nearly double, and Newton alone would crawl towards it.
    curvature = wheel.r * (1.0 - slip) * np.sin(theta_star)
    with np.errstate(divide="ignore", invalid="ignore"):
        near_max = theta_star - np.sqrt(2.0 * np.maximum(j_star, 0.0) / curvature)
        depth = np.sqrt(-2.0 * np.minimum(j_low1, 0.0) / curvature)
    near_min = np.where(low1 > -theta_star, 0.5 * (low1 + theta_star), -theta_star + depth)
    return (_monotone_root(low1, theta_star, (near_max, near_min), theta_f, slip, first, wheel),
            _monotone_root(theta_r, -theta_star, (-theta_star - depth,), theta_f, slip, second, wheel))


def _monotone_root(low: FloatArray, high: FloatArray, guesses: tuple[FloatArray, ...], theta_f: FloatArray,
                   slip: FloatArray, exists: BoolArray, wheel: Wheel, iterations: int = 50) -> FloatArray:
    """Root of jx(θ) in [low, high] where ``exists`` (jx monotone there, opposite signs at the
    ends), NaN elsewhere: Newton's method from the best of ``guesses``, falling back to
    bisection when a step leaves the bracket."""
    root = np.full(low.shape, np.nan)
    i = np.flatnonzero(exists)
    if i.size == 0:
        return root
    lo, hi, tf, kappa = low[i], high[i], theta_f[i], slip[i]
    rising = shear_displacement(hi, tf, kappa, wheel) > 0
    candidates = [np.clip(g[i], lo, hi) for g in guesses]
    residuals = [np.abs(shear_displacement(c, tf, kappa, wheel)) for c in candidates]
    theta = candidates[0]
    for c, r in zip(candidates[1:], residuals[1:]):
        theta = np.where(r < residuals[0], c, theta)
    for _ in range(iterations):
        j = shear_displacement(theta, tf, kappa, wheel)
        above = (j > 0) == rising  # the root lies below theta
        hi = np.where(above, theta, hi)
        lo = np.where(above, lo, theta)
        slope = wheel.r * ((1.0 - kappa) * np.cos(theta) - 1.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            newton = theta - j / slope
        inside = (newton >= lo) & (newton <= hi)
        new = np.where(inside, newton, 0.5 * (lo + hi))
        going = np.abs(new - theta) > 1e-12
        root[i] = theta = new
        if not going.any():
            break
        i, rising = i[going], rising[going]
        lo, hi, tf, kappa, theta = (a[going] for a in (lo, hi, tf, kappa, theta))
    return root


def _sum_over_patch(theta: FloatArray, dtheta: FloatArray, stress: Callable[[FloatArray], FloatArray],
                    theta_f: FloatArray, theta_r: FloatArray, slip: FloatArray, wheel: Wheel, soil: Soil,
                    lateral: tuple[FloatArray, FloatArray] | None) -> ContactForces:
    """Eqs. (11)-(13) as weighted sums over quadrature angles θ (M, pieces, nodes) with weights
    dθ; ``stress`` gives σ at the nodes from cos θ (broadcastable to θ's shape). ``lateral`` is
    (θr, β) of the rows for a wheel with a slip angle, None for β = 0 (then Fy = 0 and kx is
    soil.kx: the paper's computation, bit for bit). A grousered wheel shears the soil at its
    shear radius r_s and on the sides of the trapped soil (:mod:`terramechanics.grousers`): its
    shear stress counts (r_s/r) g times in Eqs. (11)-(12) and (r_s/r)² g times in Eq. (13)."""
    cos, sin = np.cos(theta), np.sin(theta)
    sigma = stress(cos)
    # Eq. (10) written out to reuse sin θ (same as shear_displacement).
    tf = theta_f[:, None, None]
    j = tf - theta
    change = np.sin(tf) - sin
    change *= (1.0 - slip)[:, None, None]
    j -= change
    if wheel.grousered:
        engagement = grouser_engagement(theta_f, theta_r, wheel)[:, None, None]
        radius = shear_radius(engagement, wheel)
        ratio = radius / wheel.r
        j *= radius
    else:
        j *= wheel.r
    kx = None if lateral is None else soil.shear_moduli(lateral[1])[0][:, None, None]
    tau = shear_stress(sigma, j, soil, kx)
    rb = wheel.r * wheel.b
    tau_torque = tau
    if wheel.grousered:
        tau = tau * (ratio * side_shear_factor(engagement, wheel))
        tau_torque = tau * ratio
    integrand = tau * sin
    integrand += sigma * cos
    fz = rb * np.einsum("ipn,ipn->i", integrand, dtheta)
    np.multiply(tau, cos, out=integrand)
    integrand -= sigma * sin
    fx = rb * np.einsum("ipn,ipn->i", integrand, dtheta)
    tx = wheel.r * rb * np.einsum("ipn,ipn->i", tau_torque, dtheta)
    if lateral is None:
        zero = np.zeros(fx.shape)
        return ContactForces(fx, fz, tx, zero, zero.copy())
    sigma_full = np.broadcast_to(sigma, theta.shape)
    fy, fy_sidewall = lateral_integrals(theta, dtheta, sigma_full, theta_f, lateral[0], slip, lateral[1], wheel, soil)
    return ContactForces(fx, fz, tx, fy, fy_sidewall)


def contact_integrals(sinkage: FloatArray, slip: FloatArray, wheel: Wheel, soil: Soil,
                      nodes: int, slip_angle: FloatArray | None = None,
                      rut: FloatArray | None = None) -> ContactForces:
    """Eqs. (11)-(13) and Fy without input checks, for callers that have already checked them;
    ``sinkage`` (below the rut's floor where there is a rut), ``slip``, ``slip_angle`` (None: 0) and
    ``rut`` (the rut's depth [m], None: 0) must broadcast."""
    beta_in = np.zeros(()) if slip_angle is None else np.asarray(slip_angle, dtype=float)
    rut_in = np.zeros(()) if rut is None else np.asarray(rut, dtype=float)
    h, kappa, beta, ruts = np.broadcast_arrays(np.asarray(sinkage, dtype=float), np.asarray(slip, dtype=float),
                                               beta_in, rut_in)
    shape = h.shape
    h, kappa, beta, ruts = h.ravel(), kappa.ravel(), beta.ravel(), ruts.ravel()
    rutted = bool(np.any(ruts != 0.0))
    lateral = bool(np.any(beta != 0.0))
    results = [np.empty(h.size) for _ in range(5)]
    # A wheel sunk past half its radius has a patch of up to π rad, over which exp(-jx/kx)
    # varies fast: it gets 1.5 times the nodes to keep the same accuracy.
    deep = h > 0.5 * wheel.r
    for group, group_nodes in ((~deep, nodes), (deep, (3 * nodes + 1) // 2)):
        index = np.flatnonzero(group)
        for start in range(0, index.size, BLOCK_SIZE):
            block = index[start:start + BLOCK_SIZE]
            _integrate_block(h[block], kappa[block], beta[block] if lateral else None, wheel, soil, group_nodes,
                             results, block, ruts[block] if rutted else None)
    return ContactForces(*(r.reshape(shape) for r in results))


def _integrate_block(h: FloatArray, kappa: FloatArray, beta: FloatArray | None, wheel: Wheel, soil: Soil,
                     nodes: int, results: list[FloatArray], into: IndexArray, rut: FloatArray | None) -> None:
    """contact_integrals on 1-D arrays small enough for the temporaries to stay in cache,
    written into ``results`` (the caller's Fx, Fz, Tx, Fy, Fy_sidewall arrays) at the indices
    ``into``; ``beta`` None for a block without slip angle, ``rut`` None for one without ruts."""
    exponent = soil.sinkage_exponent(kappa) if soil.n_slip != 0.0 else None

    def rows(values: FloatArray | None, i: IndexArray) -> FloatArray | None:
        return None if values is None else values[i, None, None]

    theta_f = entry_angle(h, wheel)
    theta_r = exit_angle(h, wheel, soil)
    theta_m = max_stress_angle(theta_f, kappa, soil)
    reversal_front, reversal_rear = _shear_reversal_angles(theta_f, theta_r, kappa, wheel)
    simple = np.isnan(reversal_front) & np.isnan(reversal_rear)

    def store(index: IndexArray, forces: ContactForces) -> None:
        for out, value in zip(results, forces):
            out[into[index]] = value

    if simple.any():
        # Two pieces split at θm. Eq. (6) at rear node u equals Eq. (5) at front node u, so σ
        # is computed on the front piece only and broadcast over both.
        i = np.flatnonzero(simple)
        theta, dtheta = _patch_nodes(np.stack([theta_r[i], theta_m[i], theta_f[i]]), ("start", "end"), nodes)
        cos_f = np.cos(theta_f[i])[:, None, None]

        def mirrored_stress(cos: FloatArray) -> FloatArray:
            return pressure_from_cosines(cos[:, 1:, :], cos_f, wheel, soil, rows(exponent, i), rows(rut, i))

        store(i, _sum_over_patch(theta, dtheta, mirrored_stress, theta_f[i], theta_r[i], kappa[i], wheel, soil,
                                 None if beta is None else (theta_r[i], beta[i])))
    if not simple.all():
        # Skidding with reversed shear somewhere in the patch: τ has a kink where jx = 0, so
        # the patch is also split there. A missing break point is put at θm, giving an empty
        # piece there, so the first piece always starts at θr and the last ends at θf.
        i = np.flatnonzero(~simple)
        m = theta_m[i]
        breaks = np.sort(np.stack([theta_r[i], np.where(np.isnan(reversal_rear[i]), m, reversal_rear[i]),
                                   np.where(np.isnan(reversal_front[i]), m, reversal_front[i]), m,
                                   theta_f[i]]), axis=0)
        theta, dtheta = _patch_nodes(breaks, ("start", "start", "end", "end"), nodes)
        tf, tr, tm = (a[i, None, None] for a in (theta_f, theta_r, theta_m))

        def stress(cos: FloatArray) -> FloatArray:
            return normal_stress(theta, tf, tr, tm, wheel, soil, rows(exponent, i), rows(rut, i))

        store(i, _sum_over_patch(theta, dtheta, stress, theta_f[i], theta_r[i], kappa[i], wheel, soil,
                                 None if beta is None else (theta_r[i], beta[i])))


def contact_forces(
    sinkage: ArrayLike, slip: ArrayLike, wheel: Wheel = Wheel(), soil: Soil = Soil(),
    nodes: int = DEFAULT_NODES, *, slip_angle: ArrayLike = 0.0, rut_depth: ArrayLike = 0.0,
) -> ContactForces:
    """Fx, Fz, Tx of a wheel at sinkage h [m] and slip ratio κ [-], Eqs. (1)-(13), and its
    lateral force Fy (with its sidewall part) at the slip angle β [rad] (Ishigami et al. 2007,
    see :mod:`terramechanics.lateral`).

    Vectorized over broadcastable ``sinkage`` (each in [0, r]), ``slip`` (each in [-1, 1]) and
    ``slip_angle`` (each in (-π/2, π/2)). ``nodes`` is the Gauss-Legendre node count on each
    piece of the patch (1.5 times as many for sinkage > r/2). At β = 0 the outputs are the
    paper's, bit for bit, and Fy = 0. ``rut_depth`` [m] (each in [0, r]; broadcasts): the rut a
    previous wheel left (multi-pass); ``sinkage`` is then the depth below the rut's floor.
    """
    check_nodes(nodes)
    h = checked_array("sinkage", sinkage, 0.0, wheel.r, "m")
    kappa = checked_array("slip", slip, -1.0, 1.0, "")
    beta = checked_array("slip_angle", slip_angle, -math.pi / 2, math.pi / 2, "rad", low_open=True)
    if np.any(np.abs(beta) >= math.pi / 2):
        raise ValueError(f"slip_angle={float(np.max(np.abs(beta)))!r} rad: expected |slip_angle| < pi/2")
    rut = checked_array("rut_depth", rut_depth, 0.0, wheel.r, "m")
    return contact_integrals(h, kappa, wheel, soil, nodes, beta, rut)
