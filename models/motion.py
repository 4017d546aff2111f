"""Motion and measurement models of a person track (world frame, metres, seconds).

State ``[x, vx, y, vy]`` (filterpy's per-dimension order): position (m) and velocity (m/s).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from people_tracker.models import compiled

# H: a person candidate measures position only
H = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])


@lru_cache(maxsize=256)
def _cv_Q(dt: float, accel_var: float) -> np.ndarray:
    Q = constant_velocity_Q(dt, accel_var)
    Q.setflags(write=False)
    return Q


def constant_velocity_step(dt: float, accel_var: float) -> tuple[float, np.ndarray]:
    """``dt`` rounded to the nanosecond, and Q over it, shared (read-only) by every track
    predicted over the same step (stamps' jitter makes most steps' ``dt`` a new one)."""
    dt = round(dt, 9)
    return dt, _cv_Q(dt, accel_var)


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
    a, b, c = 0.25 * dt ** 4 * accel_var, 0.5 * dt ** 3 * accel_var, dt ** 2 * accel_var
    return np.array([[a, b, 0.0, 0.0], [b, c, 0.0, 0.0], [0.0, 0.0, a, b], [0.0, 0.0, b, c]])


# The track filter's two steps written out for the model above (state [x, vx, y, vy], H
# measuring x and y): filterpy's ``KalmanFilter.predict`` and ``update`` do the same
# arithmetic through a dozen small matrix products, an inverse and a deep copy (about 3
# and 11 microseconds a call), where the work is a few dozen multiplications. Each step is
# Python arithmetic on the 4x4's elements as floats, and a compiled kernel (numba, the
# ``[fast]`` extra) doing the same operations in the same order, so the two agree to the
# bit (``tests/detection/test_compiled.py``); both equal filterpy's to 1e-9
# (``tests/tracker/test_motion.py``: filterpy multiplies whole matrices and inverts by LU,
# so the last bits differ). The filter's state stays in a filterpy ``KalmanFilter``, whose
# ``x`` and ``P`` are replaced, not written into, as filterpy does.

def cv_predict(x: np.ndarray, P: np.ndarray, dt: float, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The constant-velocity prediction over ``dt`` seconds: x = F x; P = F P Fᵀ + Q, with
    F = :func:`constant_velocity_F` (``dt``) and ``Q`` its process noise (m², m²/s, m²/s²).
    Returns new arrays."""
    if compiled.on:
        return _predict_kernel(x, P, float(dt), Q)
    # Python floats (a 4x4 is too small for numpy's calls to pay), element by element as the kernel
    x0, x1, x2, x3 = x.tolist()
    (p00, p01, p02, p03), (p10, p11, p12, p13), (p20, p21, p22, p23), (p30, p31, p32, p33) = P.tolist()
    q = Q.tolist()
    # x = F x: each position moves by its velocity times dt
    xn = [x0 + dt * x1, x1, x2 + dt * x3, x3]
    # F P: the position rows gain dt times the velocity rows
    f = [[p00 + dt * p10, p01 + dt * p11, p02 + dt * p12, p03 + dt * p13], [p10, p11, p12, p13],
         [p20 + dt * p30, p21 + dt * p31, p22 + dt * p32, p23 + dt * p33], [p30, p31, p32, p33]]
    # (F P) Fᵀ: the position columns gain dt times the velocity columns; then + Q
    Pn = [[(r[0] + dt * r[1]) + qr[0], r[1] + qr[1], (r[2] + dt * r[3]) + qr[2], r[3] + qr[3]] for r, qr in zip(f, q)]
    return np.array(xn), np.array(Pn)


def _predict_loop(x, P, dt, Q):
    """:func:`cv_predict`'s Python code in a loop (compiled by numba): the same operations."""
    xn = x.copy()
    for i in (0, 2):
        xn[i] = x[i] + dt * x[i + 1]
    FP = P.copy()
    for i in (0, 2):
        for j in range(4):
            FP[i, j] = P[i, j] + dt * P[i + 1, j]
    Pn = np.empty((4, 4))
    for i in range(4):
        for j in range(4):
            m = FP[i, j] + dt * FP[i, j + 1] if j % 2 == 0 else FP[i, j]
            Pn[i, j] = m + Q[i, j]
    return xn, Pn


def position_update(x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The update with a measured position ``z`` (x, y; m) of covariance ``R`` (2, 2; m²),
    H = :data:`H`: y = z - H x; S = H P Hᵀ + R; K = P Hᵀ S⁻¹; x = x + K y; and the
    covariance in Joseph's form, as filterpy keeps it, P = (I - K H) P (I - K H)ᵀ + K R Kᵀ.
    Returns new arrays."""
    if compiled.on:
        return _update_kernel(x, P, z, R)
    x, p, (r00, r01), (r10, r11) = x.tolist(), P.tolist(), *R.tolist()
    # S = H P Hᵀ + R (H picks rows and columns 0 and 2), and its inverse written out
    s00, s01, s10, s11 = p[0][0] + r00, p[0][2] + r01, p[2][0] + r10, p[2][2] + r11
    det = s00 * s11 - s01 * s10
    i00, i01, i10, i11 = s11 / det, -s01 / det, -s10 / det, s00 / det
    # K = P Hᵀ S⁻¹
    k0 = [row[0] * i00 + row[2] * i10 for row in p]
    k1 = [row[0] * i01 + row[2] * i11 for row in p]
    # x = x + K (z - H x)
    y0, y1 = float(z[0]) - x[0], float(z[1]) - x[2]
    xn = [x[i] + (k0[i] * y0 + k1[i] * y1) for i in range(4)]
    # A P, with A = I - K H: each row i loses K[i] times P's rows 0 and 2
    ap = [[p[i][j] - k0[i] * p[0][j] - k1[i] * p[2][j] for j in range(4)] for i in range(4)]
    # (A P) Aᵀ: each column j loses K[j] times (A P)'s columns 0 and 2; + K R Kᵀ
    Pn = []
    for i in range(4):
        kr0, kr1 = k0[i] * r00 + k1[i] * r10, k0[i] * r01 + k1[i] * r11
        a = ap[i]
        Pn.append([(a[j] - a[0] * k0[j] - a[2] * k1[j]) + (kr0 * k0[j] + kr1 * k1[j]) for j in range(4)])
    return np.array(xn), np.array(Pn)


def _update_loop(x, P, z, R):
    """:func:`position_update`'s Python code in a loop (compiled by numba): the same operations."""
    s00, s01, s10, s11 = P[0, 0] + R[0, 0], P[0, 2] + R[0, 1], P[2, 0] + R[1, 0], P[2, 2] + R[1, 1]
    det = s00 * s11 - s01 * s10
    i00, i01, i10, i11 = s11 / det, -s01 / det, -s10 / det, s00 / det
    k0, k1 = np.empty(4), np.empty(4)
    for i in range(4):
        k0[i] = P[i, 0] * i00 + P[i, 2] * i10
        k1[i] = P[i, 0] * i01 + P[i, 2] * i11
    y0, y1 = z[0] - x[0], z[1] - x[2]
    xn = np.empty(4)
    for i in range(4):
        xn[i] = x[i] + (k0[i] * y0 + k1[i] * y1)
    AP = np.empty((4, 4))
    for i in range(4):
        for j in range(4):
            AP[i, j] = P[i, j] - k0[i] * P[0, j] - k1[i] * P[2, j]
    Pn = np.empty((4, 4))
    for i in range(4):
        kr0 = k0[i] * R[0, 0] + k1[i] * R[1, 0]
        kr1 = k0[i] * R[0, 1] + k1[i] * R[1, 1]
        for j in range(4):
            Pn[i, j] = (AP[i, j] - AP[i, 0] * k0[j] - AP[i, 2] * k1[j]) + (kr0 * k0[j] + kr1 * k1[j])
    return xn, Pn


_predict_kernel = compiled.njit(_predict_loop)
_update_kernel = compiled.njit(_update_loop)
