"""Motion and measurement models of a person track (world frame, metres, seconds).

State ``[x, vx, y, vy]`` (filterpy's per-dimension order): position (m) and velocity (m/s).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

# H: a person candidate measures position only
H = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])


@lru_cache(maxsize=256)
def _cv(dt: float, accel_var: float) -> tuple[np.ndarray, np.ndarray]:
    F = constant_velocity_F(dt)
    Q = constant_velocity_Q(dt, accel_var)
    F.setflags(write=False)
    Q.setflags(write=False)
    return F, Q


def constant_velocity_FQ(dt: float, accel_var: float) -> tuple[np.ndarray, np.ndarray]:
    """F and Q for ``dt`` seconds, shared (read-only) by every track predicted over the same step."""
    return _cv(round(dt, 9), accel_var)


def constant_velocity_F(dt: float) -> np.ndarray:
    """State transition over ``dt`` seconds: x' = x + vx·dt, vx' = vx (each axis)."""
    f = np.array([[1.0, dt], [0.0, 1.0]])
    return np.kron(np.eye(2), f)


def constant_velocity_Q(dt: float, accel_var: float) -> np.ndarray:
    """Process noise of a white-noise acceleration of variance ``accel_var`` ((m/s²)²), over ``dt`` s.

    filterpy's ``Q_discrete_white_noise(dim=2, dt, var, block_size=2)``, element for element
    (``tests/tracker/test_motion.py`` checks it), written out: filterpy builds it with
    scipy's ``block_diag`` at ~0.3 ms a call, and stamps that jitter make every step's
    ``dt`` a new one.
    """
    q = np.array([[0.25 * dt ** 4, 0.5 * dt ** 3], [0.5 * dt ** 3, dt ** 2]])
    return np.kron(np.eye(2), q) * accel_var
