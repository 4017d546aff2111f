"""The track motion model written out by hand equals filterpy's, element for element, and
the track filter's predict and update steps equal filterpy's to 1e-9."""

from contextlib import nullcontext

import numpy as np
import pytest
from filterpy.common import Q_discrete_white_noise
from filterpy.kalman import KalmanFilter

from people_tracker.models import compiled
from people_tracker.models.motion import H, constant_velocity_F, constant_velocity_Q, cv_predict, position_update


@pytest.mark.parametrize("dt", [1e-3, 0.0667, 0.1334, 0.45, 2.0, 37.5])
@pytest.mark.parametrize("var", [0.25, 1.0, 4.0])
def test_constant_velocity_Q_is_filterpys(dt, var):
    ours = constant_velocity_Q(dt, var)
    theirs = Q_discrete_white_noise(dim=2, dt=dt, var=var, block_size=2)
    assert ours.shape == (4, 4)
    assert np.array_equal(ours, theirs)


def _random_filter(rng):
    """A filterpy filter at a random state: a random covariance, well or badly conditioned."""
    kf = KalmanFilter(dim_x=4, dim_z=2)
    kf.H = H.copy()
    kf.x = rng.normal(0, [5, 1.5, 5, 1.5])
    A = rng.normal(size=(4, 4)) * 10.0 ** rng.uniform(-3, 0.5, 4)
    kf.P = A @ A.T + np.diag(10.0 ** rng.uniform(-6, 0, 4))
    return kf


def _close(ours, theirs, what):
    scale = max(1.0, float(np.abs(theirs).max()))
    assert np.abs(ours - theirs).max() <= 1e-9 * scale, f"{what}: differ by {np.abs(ours - theirs).max()}"


@pytest.mark.parametrize("kernels", [True, False], ids=["compiled", "numpy"])
def test_the_filter_steps_equal_filterpys(kernels):
    """A thousand random tracks predicted and updated by filterpy and by ours, many steps in
    a row (the errors would add up), with and without the compiled kernels."""
    if kernels and not compiled.ENABLED:
        pytest.skip("numba is not installed (the [fast] extra): only the numpy path runs")
    rng = np.random.default_rng(3)
    for k in range(1000):
        kf = _random_filter(rng)
        x, P = kf.x.copy(), kf.P.copy()
        for step in range(5):
            dt = float(rng.choice([0.0133, 0.0667, 0.1, 0.45, 2.0]))
            Q = constant_velocity_Q(dt, float(rng.uniform(0.1, 4.0)))
            kf.predict(F=constant_velocity_F(dt), Q=Q)
            with compiled.numpy_only() if not kernels else nullcontext():
                x, P = cv_predict(x, P, dt, Q)
            _close(x, kf.x, f"predict {k}.{step}: x")
            _close(P, kf.P, f"predict {k}.{step}: P")
            z = kf.x[::2] + rng.normal(0, 0.3, 2)
            c = rng.uniform(-0.5, 0.5) * 1e-3
            R = np.array([[rng.uniform(1e-4, 0.05), c], [c, rng.uniform(1e-4, 0.05)]])
            kf.update(z, R=R)
            with compiled.numpy_only() if not kernels else nullcontext():
                x, P = position_update(x, P, z, R)
            _close(x, kf.x, f"update {k}.{step}: x")
            _close(P, kf.P, f"update {k}.{step}: P")
            assert np.allclose(P, P.T, rtol=0, atol=1e-12)

