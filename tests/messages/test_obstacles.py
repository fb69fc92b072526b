"""messages.obstacles: circles, planes and cylinders are the solids ``wbc`` accepts, and come
back as them."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from messages import Circle
from messages.obstacles import Cylinder, Plane, Solids
from wbc.geometry import obstacles3d


def test_obstacle_radius_is_positive() -> None:
    with pytest.raises(ValidationError, match="radius"):
        Circle(x=0.0, y=0.0, radius=0.0)


def test_a_plane_must_be_a_solid_wbc_accepts() -> None:
    """A unit normal, and a footprint only on a horizontal plane, convex: the error names the
    field, as wbc.geometry.obstacles3d does."""
    with pytest.raises(ValidationError, match="normal: expected a unit vector"):
        Plane(normal=(0.0, 0.0, 2.0), offset=0.4)
    with pytest.raises(ValidationError, match="footprint: only a horizontal plane"):
        Plane(normal=(1.0, 0.0, 0.0), offset=0.4, footprint=((0, 0), (1, 0), (1, 1)))
    with pytest.raises(ValidationError, match="radius"):
        Cylinder(x=0.0, y=0.0, radius=-0.1)
    with pytest.raises(ValidationError, match="radius"):
        Cylinder(x=0.0, y=0.0, radius=1e300)


def test_solids_come_back_as_the_wbc_obstacles_they_were_made_of() -> None:
    solids = (
        obstacles3d.Plane((0.0, 0.0, 1.0), 0.4, ((0.5, -0.4), (1.1, -0.4), (1.1, 0.4))),
        obstacles3d.Cylinder(0.2, -0.3, 0.05, None, "pole"),
    )
    assert Solids.of(solids).solids() == solids
