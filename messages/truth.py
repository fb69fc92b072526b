"""What really happened in the simulator, for tests and reports only.

No estimator or controller may read it (the runtime refuses them): they see the world only
through the sensors, as on the real robot.
"""

from __future__ import annotations

from messages.base import ArmVector, Count, Message, UnitDualQuaternion, Vector3
from messages.header import Header


class SimTruth(Message):
    """The simulated robot in the simulator's world frame: ``base_pose`` (x, y, phi) in m, m,
    rad, ``arm_joints`` in rad, the ``end_effector`` pose, the number of ``contacts`` between
    the base and an obstacle so far and whether one holds now (``in_contact``)."""

    header: Header
    base_pose: Vector3
    arm_joints: ArmVector
    end_effector: UnitDualQuaternion
    contacts: Count
    in_contact: bool
