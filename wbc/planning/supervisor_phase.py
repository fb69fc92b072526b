"""The phases of the staging supervisor (``wbc.planning.staging_supervisor``), on their own so that
a message schema names them without importing the planner."""

from __future__ import annotations

from enum import StrEnum


class Phase(StrEnum):
    """The phases in the order they run (``StagingSupervisor._advance`` follows it from DRIVE
    on); PLANNING comes before the first drive and every re-plan, UNREACHABLE can end any."""

    PLANNING = "planning"
    DRIVE = "drive"
    TURN = "turn"
    APPROACH = "approach"
    ALIGN = "align"
    POSE = "pose"
    REACHED = "reached"
    UNREACHABLE = "unreachable"
