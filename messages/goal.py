"""The task given to a controller."""

from __future__ import annotations

from typing import Literal

from pydantic import model_validator

from messages.base import ArmVector, Finite, Message, Positive, UnitDualQuaternion, Vector3
from messages.header import Header

TASK_FIELDS = {
    "pose": ("pose",),
    "position": ("position",),
    "point": ("point", "arm", "lookahead"),
    "heading": ("heading", "arm", "point"),
}
"""The fields each kind of task needs; every other target field must be left out."""


class Goal(Message):
    """A task for a controller, with optional controller gains.

    ``pose``: the end-effector pose ``pose`` (a unit dual quaternion). ``position``: the
    end-effector position ``position`` (m). ``point``: the point ``lookahead`` (m) ahead of
    the wheel axle to ``point`` (x, y) with the arm going to ``arm`` (rad). ``heading``: the
    base turned to ``heading`` (rad) where it stands, at ``point``, the arm going to ``arm``
    (the legs of a staging plan, ``wbc.planning.drive_tasks``). ``eta`` is the error gain (1/s) and
    ``beta`` the bound of ``||u||_1 <= beta ||e'||_1`` (5.10); ``None`` keeps the
    controller's own.
    """

    header: Header
    task: Literal["pose", "position", "point", "heading"]
    pose: UnitDualQuaternion | None = None
    position: Vector3 | None = None
    point: tuple[Finite, Finite] | None = None
    heading: Finite | None = None
    arm: ArmVector | None = None
    lookahead: Positive | None = None
    eta: Positive | None = None
    beta: Positive | None = None

    @model_validator(mode="after")
    def _target_matches_task(self) -> Goal:
        needed = TASK_FIELDS[self.task]
        for name in {f for fields in TASK_FIELDS.values() for f in fields}:
            given = getattr(self, name) is not None
            if given != (name in needed):
                article = "an" if name[0] in "aeiou" else "a"
                what = "takes no" if given else f"needs {article}"
                raise ValueError(f"a {self.task} task {what} {name} (it needs {', '.join(needed)})")
        return self
