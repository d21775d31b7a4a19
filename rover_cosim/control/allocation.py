"""Force allocation: the body's force and yaw-moment demand shared among the wheels.

Each wheel i at (x_i, y_i) [m] from the centre of gravity takes a force (f_x,i, f_y,i) [N] in
the body's heading frame. Of all shares that give the demand exactly,

    sum f_x,i = F_x,   sum f_y,i = F_y,   sum (x_i f_y,i - y_i f_x,i) = M_z,

the allocation takes the one that minimises sum (f_x,i^2 + f_y,i^2) / W_i: least squares
weighted by the wheel loads W_i [N], so a wheel carries force in proportion to its load (what
the soil under it can bear: the thrust limit c A + W tan(phi) grows with W). Closed form:
f = D A^T (A D A^T)^-1 b with D = diag(W), in plain floats (``share``), as its C twin computes it.
"""

from __future__ import annotations

import numpy as np


def allocation_matrix(x_hub: np.ndarray, y_hub: np.ndarray) -> np.ndarray:
    """A (3, 2n): rows sum f_x, sum f_y, yaw moment; columns f_x,1..n then f_y,1..n."""
    n = len(x_hub)
    return np.vstack([np.concatenate([np.ones(n), np.zeros(n)]), np.concatenate([np.zeros(n), np.ones(n)]),
                      np.concatenate([-np.asarray(y_hub, float), np.asarray(x_hub, float)])])


def allocate(demand: np.ndarray, matrix: np.ndarray, loads: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(f_x, f_y) per wheel [N] for ``demand`` = (F_x [N], F_y [N], M_z [N·m]) at ``loads`` [N];
    a wheel without load (lifted) gets no force. Raises when fewer than two wheels carry load."""
    fx, fy = share(list(map(float, demand)), np.asarray(matrix, float).tolist(), list(map(float, loads)))
    return np.array(fx), np.array(fy)


def share(demand: list[float], rows: list[list[float]], loads: list[float]) -> tuple[list[float], list[float]]:
    """:func:`allocate` in plain floats, in the order of operations its C twin
    (``path_controller.c``) repeats: G = A D A^T summed column by column, G z = demand by
    Gaussian elimination with partial pivoting, f = D A^T z."""
    weights = [0.0 if 0.0 > w else w for w in loads]  # np.clip(loads, 0, None), NaN kept
    if sum(1 for w in weights if w != 0.0) < 2:
        raise ValueError(f"loads = {loads!r} N: at least two wheels must carry load to allocate a yaw moment")
    d = weights + weights
    columns = len(d)
    scaled = [[row[k] * d[k] for k in range(columns)] for row in rows]
    gram = [[0.0] * 3 for _ in range(3)]
    for p in range(3):
        for q in range(3):
            total = 0.0
            for k in range(columns):
                total += scaled[p][k] * rows[q][k]
            gram[p][q] = total
    z = solve3(gram, demand)
    forces = [scaled[0][k] * z[0] + scaled[1][k] * z[1] + scaled[2][k] * z[2] for k in range(columns)]
    n = len(weights)
    return forces[:n], forces[n:]


def solve3(matrix: list[list[float]], b: list[float]) -> list[float]:
    """x with ``matrix`` x = ``b`` (3 x 3): Gaussian elimination with partial pivoting (the first
    largest pivot), then back substitution. ValueError for a singular matrix."""
    a = [list(row) + [value] for row, value in zip(matrix, b)]
    for k in range(3):
        p = k
        for i in range(k + 1, 3):
            if abs(a[i][k]) > abs(a[p][k]):
                p = i
        if a[p][k] == 0.0:
            raise ValueError(f"matrix {matrix!r}: singular, the allocation has no unique solution")
        a[k], a[p] = a[p], a[k]
        for i in range(k + 1, 3):
            factor = a[i][k] / a[k][k]
            for j in range(k, 4):
                a[i][j] -= factor * a[k][j]
    x2 = a[2][3] / a[2][2]
    x1 = (a[1][3] - a[1][2] * x2) / a[1][1]
    x0 = (a[0][3] - a[0][1] * x1 - a[0][2] * x2) / a[0][0]
    return [x0, x1, x2]
