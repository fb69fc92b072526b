"""The simulator process says, one line per solid, when the robot starts inside a solid of
its scene, and what the robot will do (wbc.geometry.start_inside); a clear start says nothing of
it."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import pytest
import yaml

from profiles.deploy_files import DEPLOY
from wbc.geometry.start_inside import CONSEQUENCE

if TYPE_CHECKING:
    from tests.components.conftest import System

SLAB = {"name": "slab", "normal": [0, 0, 1], "offset": 0.3}
"""Everything below 0.3 m, wherever F0 lies: the base of any start is inside it."""
POLE = {"name": "pole", "x": 5.0, "y": 5.0, "radius": 0.05, "height": 1.0}
"""Far from the start."""


def sim_with(arm_obstacles: dict) -> str:
    """deploy/sim.yaml's text with these solids in its scene."""
    data = yaml.safe_load((DEPLOY / "sim.yaml").read_text())
    data["scene"]["arm_obstacles"] = arm_obstacles
    return yaml.safe_dump(data, sort_keys=False)


@pytest.mark.parametrize("planes", [[SLAB], []], ids=["through the robot", "clear"])
def test_a_start_inside_a_solid_is_warned_of_in_one_line_naming_it(
    deployed: Callable[[str], System], planes: list
) -> None:
    system = deployed(sim_with({"planes": planes, "cylinders": [POLE]}))
    liveliness = system.liveliness()
    system.start("simulator")
    liveliness.wait_for("simulator", alive=True)  # warned while it starts, before it is alive
    lines = [
        line for line in system.log("simulator").splitlines() if "the robot starts inside" in line
    ]
    if not planes:
        assert lines == []
        return
    assert len(lines) == 1, lines
    assert "the robot starts inside 'slab' (scene.arm_obstacles.planes[0]): its base" in lines[0]
    assert lines[0].endswith(CONSEQUENCE)
