"""A hand's command of the robot (``parsimony teleop``, the control station's Teleop channel)."""

from __future__ import annotations

from messages.base import Finite, Message
from messages.header import Header


class TeleopCommand(Message):
    """Drive the base ``forward`` (m/s) and ``turn`` (rad/s), and move the arm's joint named
    ``joint`` (none: ``""``) at ``joint_velocity`` (rad/s or m/s). The controller turns it into
    commands under the robot's velocity and joint limits while it keeps coming (its dead-man
    timeout), and yields its goal to it until a new goal."""

    header: Header
    forward: Finite = 0.0
    turn: Finite = 0.0
    joint: str = ""
    joint_velocity: Finite = 0.0
