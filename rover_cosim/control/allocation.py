"""Force allocation: the body's force and yaw-moment demand shared among the wheels.

Each wheel i at (x_i, y_i) [m] from the centre of gravity takes a force (f_x,i, f_y,i) [N] in
the body's heading frame. Of all shares that give the demand exactly,

    sum f_x,i = F_x,   sum f_y,i = F_y,   sum (x_i f_y,i - y_i f_x,i) = M_z,

the allocation takes the one that minimises sum (f_x,i^2 + f_y,i^2) / W_i: least squares
weighted by the wheel loads W_i [N], so a wheel carries force in proportion to its load (what
the soil under it can bear: the thrust limit c A + W tan(phi) grows with W). Closed form:
f = D A^T (A D A^T)^-1 b with D = diag(W).
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
    weights = np.clip(np.asarray(loads, float), 0.0, None)
    if np.count_nonzero(weights) < 2:
        raise ValueError(f"loads = {loads!r} N: at least two wheels must carry load to allocate a yaw moment")
    d = np.concatenate([weights, weights])
    scaled = matrix * d
    forces = scaled.T @ np.linalg.solve(scaled @ matrix.T, np.asarray(demand, float))
    n = len(weights)
    return forces[:n], forces[n:]
