"""What the supervisor knows of the robot state, and where the ceiling camera sees the base.

The state is ``none`` (none yet, or none for ``timeout_s``), ``valid``, ``degraded`` (valid,
the base pose carried by odometry alone) or ``invalid`` (no camera fix), each since the stamp
of the first state so (``messages.supervisor.StateName``). With the profile's scene, the camera
sees the base's marker wholly where the base's axle keeps ``margin`` inside the floor its image
covers at the marker's height: the marker's offset from the axle and its half diagonal (the
base may face any way).
"""

from __future__ import annotations

import math
from typing import Any

from messages.state import RobotState
from profiles.scene import Scene
from sim2d.floor_view import Region, camera_region
from sim2d.pinhole import ceiling_camera


def sight_region(scene: Scene | None) -> Region:
    """Where the base's axle stays for the scene's camera to see its marker, in F0; empty
    without a scene."""
    if scene is None:
        return ()
    base = scene.base
    margin = math.hypot(*base.offset) + base.size_m / math.sqrt(2.0)
    return camera_region(ceiling_camera(scene.camera), scene.reference_pose, base.height_m, margin)


class RobotSight:
    """The latest robot state's validity and fix, as ``saw`` is told of each."""

    def __init__(self, scene: Scene | None, timeout_s: float) -> None:
        self.region = sight_region(scene)
        self.timeout_s = timeout_s
        self.name = "none"
        self.since_ns: int | None = None
        self.last_ns: int | None = None
        """The stamp of the latest state."""
        self.no_fix_s: float | None = None
        """How long the camera had not fixed the base at the latest state, s (None: it just
        had; 0 with no fix ever)."""

    def saw(self, state: RobotState) -> None:
        name = "invalid" if not state.valid else "degraded" if state.degraded else "valid"
        stamp = state.header.stamp_ns
        if name != self.name:
            self.name, self.since_ns = name, stamp
        self.last_ns = stamp
        self.no_fix_s = None if name == "valid" else state.age_s

    def stale(self, now_ns: int) -> bool:
        """No state for ``timeout_s`` (or none yet)."""
        return self.last_ns is None or now_ns - self.last_ns > self.timeout_s * 1e9

    def state(self, now_ns: int) -> str:
        return "none" if self.stale(now_ns) else self.name

    def missing(self, now_ns: int) -> str:
        """Why there is no valid state at ``now_ns``, in words; empty when there is one."""
        if self.last_ns is None:
            return "no robot state on robot/state yet"
        if self.stale(now_ns):
            return f"no robot state on robot/state for {(now_ns - self.last_ns) / 1e9:.1f} s"
        if self.name != "invalid":
            return ""
        fix = (
            f"no camera fix of the base for {self.no_fix_s:.1f} s"
            if self.no_fix_s
            else "no camera fix of the base yet"
        )
        return f"no valid robot state for {self._for_s(now_ns):.1f} s ({fix})"

    def fields(self, now_ns: int) -> dict[str, Any]:
        """The status's fields of the state (``messages.supervisor.SupervisorStatus``)."""
        state = self.state(now_ns)
        since = self.last_ns if state == "none" else self.since_ns
        warning = ""
        if state == "degraded":
            warning = (
                f"the camera has not fixed the base for {self.no_fix_s:.1f} s: its pose "
                "is odometry alone"
            )
        return {
            "state": state,
            "state_since_s": None if since is None else since / 1e9,
            "no_fix_s": self.no_fix_s if state in ("degraded", "invalid") else None,
            "warning": warning,
        }

    def _for_s(self, now_ns: int) -> float:
        return max(0.0, (now_ns - (self.since_ns or now_ns)) / 1e9)
