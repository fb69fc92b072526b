"""The scene of deploy/sim.yaml, its ceiling camera and the markers a set-up places in it, for
the tests of the simulated set-ups (Little John's and those derived for the zoo)."""

from __future__ import annotations

import math
from pathlib import Path

from profiles.profile import load_profile
from profiles.scene import Scene
from sim2d.pinhole import PinholeCamera, ceiling_camera
from sim2d.scenarios import SimScenario

REPO = Path(__file__).resolve().parents[2]
SCENE = load_profile(REPO / "deploy/sim.yaml").scene


def scene() -> Scene:
    assert SCENE is not None
    return SCENE


def camera() -> PinholeCamera:
    return ceiling_camera(scene().camera)


def markers(setup: SimScenario) -> list[tuple[str, float, float, float, float]]:
    """(what, x, y, height, size) of every marker: F0, F1 on the base at its start, F2, F3."""
    s = scene()
    x, y, phi = setup.start[:3]
    ox, oy = s.base.offset
    c, s_ = math.cos(phi), math.sin(phi)
    base = (x + c * ox - s_ * oy, y + s_ * ox + c * oy)
    found = [
        ("reference", *s.reference_pose[:2], s.reference.height_m, s.reference.size_m),
        ("base", *base, s.base.height_m, s.base.size_m),
        ("bin", *setup.bin[:2], setup.goal_height or s.goal.height_m, s.goal.size_m),
    ]
    found += [
        ("obstacle", c.x, c.y, s.obstacles.height_m, s.obstacles.size_m) for c in setup.obstacles
    ]
    return found
