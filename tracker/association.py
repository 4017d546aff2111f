"""Association of person candidates to tracks: Mahalanobis gating, then nearest neighbour
(greedy) or global nearest neighbour (optimal assignment)."""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

_FAR = 1e12


def mahalanobis_costs(means: np.ndarray, covs: np.ndarray, z: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Squared Mahalanobis distance of every candidate to every track's predicted position.

    Parameters
    ----------
    means : ndarray, shape (t, 2)
        Predicted positions H x, metres.
    covs : ndarray, shape (t, 2, 2)
        Their covariances H P Hᵀ, m².
    z : ndarray, shape (c, 2)
        Candidate positions, metres.
    R : ndarray, shape (c, 2, 2)
        Candidate measurement covariances, m².

    Returns
    -------
    ndarray, shape (t, c)
    """
    # S = H P Hᵀ + R ;  d² = yᵀ S⁻¹ y with y = z - H x
    S = covs[:, None, :, :] + R[None, :, :, :]
    y = z[None, :, :] - means[:, None, :]
    sol = np.linalg.solve(S, y[..., None])[..., 0]
    return np.einsum("tci,tci->tc", y, sol)


def associate(cost: np.ndarray, gate: float, method: str = "gnn") -> list[tuple[int, int]]:
    """(track, candidate) pairs whose cost is within ``gate``.

    ``nn``: repeatedly take the cheapest remaining pair (greedy nearest neighbour);
    ``gnn``: the assignment of least total cost (``scipy.optimize.linear_sum_assignment``).
    """
    if cost.size == 0:
        return []
    if method == "gnn":
        c = np.where(cost <= gate, cost, _FAR)
        rows, cols = linear_sum_assignment(c)
        return [(int(r), int(k)) for r, k in zip(rows, cols) if c[r, k] < _FAR]
    if method != "nn":
        raise ValueError(f"association method must be nn or gnn, got {method!r}")
    pairs = []
    used_t, used_c = set(), set()
    flat = np.argsort(cost, axis=None, kind="stable")
    for f in flat:
        t, k = np.unravel_index(f, cost.shape)
        if cost[t, k] > gate:
            break
        if t in used_t or k in used_c:
            continue
        pairs.append((int(t), int(k)))
        used_t.add(t)
        used_c.add(k)
    return pairs
