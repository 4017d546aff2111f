"""The track motion model written out by hand equals filterpy's, element for element."""

import numpy as np
import pytest
from filterpy.common import Q_discrete_white_noise

from people_tracker.models.motion import constant_velocity_Q


@pytest.mark.parametrize("dt", [1e-3, 0.0667, 0.1334, 0.45, 2.0, 37.5])
@pytest.mark.parametrize("var", [0.25, 1.0, 4.0])
def test_constant_velocity_Q_is_filterpys(dt, var):
    ours = constant_velocity_Q(dt, var)
    theirs = Q_discrete_white_noise(dim=2, dt=dt, var=var, block_size=2)
    assert ours.shape == (4, 4)
    assert np.array_equal(ours, theirs)
