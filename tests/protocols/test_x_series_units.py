"""The X-series servos' units (protocols/x_series_units.py): angles and speeds in and out of the
control table's values."""

from __future__ import annotations

import math

import pytest

from protocols import dynamixel_v2 as dxl
from protocols import x_series_units as x_units


def test_units_of_the_x_series() -> None:
    assert x_units.position_units(0.0) == 2048
    assert x_units.position_units(math.pi / 2) == 3072
    assert x_units.position_units(-10.0) == 0 and x_units.position_units(10.0) == 4095
    assert abs(x_units.angle_of_units(1024) + math.pi / 2) < 1e-12
    assert x_units.profile_velocity(0.0) is None and x_units.profile_velocity(-0.01) is None
    assert x_units.profile_velocity(1.0) == round(1.0 / (0.229 * 2 * math.pi / 60))
    assert x_units.velocity_units(-1.0) == -x_units.velocity_units(1.0)
    assert dxl.signed(dxl.value(-3, 4)) == -3
    with pytest.raises(ValueError, match="non-finite"):
        x_units.position_units(math.nan)
