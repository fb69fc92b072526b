"""What really happened in the simulator, for tests and reports only.

No estimator or controller may read it (the runtime refuses them): they see the world only
through the sensors, as on the real robot.
"""

from __future__ import annotations

from pydantic import Field

from messages.base import ArmVector, Count, Message, UnitDualQuaternion, Vector3
from messages.header import Header
from messages.obstacles import MAX_CIRCLES, Circle, Solids


class SimTruth(Message):
    """The simulated robot in the simulator's world frame: ``base_pose`` (x, y, phi) in m, m,
    rad, ``arm_joints`` in rad, the ``end_effector`` pose, the number of ``contacts`` between
    the base and an obstacle so far and whether one holds now (``in_contact``); and the scene
    as placed: the ``goal`` x_d (eq. 6.3: the bin marker's pose times the scene's offset), the
    reference marker F0's pose (x, y, yaw) and the ``obstacles``, so that a recording can be
    judged from the file alone (``analysis.judge``). Recordings made before these fields read
    with none."""

    header: Header
    base_pose: Vector3
    arm_joints: ArmVector
    end_effector: UnitDualQuaternion
    contacts: Count
    in_contact: bool
    goal: UnitDualQuaternion | None = None
    reference_pose: Vector3 | None = None
    obstacles: tuple[Circle, ...] = Field(default=(), max_length=MAX_CIRCLES)
    solids: Solids = Solids()
    arm_penetrations: Count = 0
    arm_penetrating: bool = False

    def configuration(self) -> list[float]:
        """The true whole-body configuration ``q = [x, y, phi, q1, ..., qn]``."""
        return [*self.base_pose, *self.arm_joints]
