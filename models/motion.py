"""Motion and measurement models of a person track (world frame, metres, seconds).

State ``[x, vx, y, vy]`` (filterpy's per-dimension order): position (m) and velocity (m/s).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from filterpy.common import Q_discrete_white_noise

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
    """Process noise of a white-noise acceleration of variance ``accel_var`` ((m/s²)²), over ``dt`` s."""
    return Q_discrete_white_noise(dim=2, dt=dt, var=accel_var, block_size=2)
