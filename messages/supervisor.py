"""What the staging supervisor is doing for the operator's goal."""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from messages.base import ArmVector, Finite, Message, NonNegative
from messages.header import Header
from messages.obstacles import MAX_CIRCLES
from wbc.supervisor_phase import Phase

PhaseName = Literal[("idle", *(phase.value for phase in Phase))]  # type: ignore[valid-type]
"""``idle`` before any goal, then one of ``wbc.supervisor_phase.Phase``."""

MAX_WAY = 8 * MAX_CIRCLES + 3
"""The most points a status's way may hold: a planned way passes each of at most
``MAX_CIRCLES`` discs once, on an arc drawn as at most 8 corners (``wbc.drive_planner``'s
pieces of at most pi/4), between the point the base left its start for, the staging point and
the candidate's base."""


class SupervisorStatus(Message):
    """The phase of the current goal (``wbc.staging_supervisor``), published as it changes and
    with every control-rate tick that follows.

    ``phase`` is a ``PhaseName``; ``candidate`` numbers the staging candidate being driven to
    (1 the best), ``candidate_base`` is its base pose (x, y, phi) and ``candidate_arm`` its arm
    joints (rad); ``way`` is where the base has still to pass, in order (x, y): the waypoints
    of its planned way from the current leg's (the staging point last) while it drives, then
    the candidate's base (empty with no candidate);
    ``plans``, ``replans`` and ``stalls`` count since the goal came; ``reason`` says why a goal
    is unreachable;
    ``last_event`` is the latest thing the supervisor did, in words; ``planning_ms`` is the
    time of the last plan; ``refusals`` counts the requests refused as malformed since the
    supervisor started, ``last_refusal`` says why the latest was (a refused request leaves
    the current goal as it is).
    """

    header: Header
    phase: PhaseName
    candidate: int = Field(ge=0)
    candidate_base: tuple[Finite, Finite, Finite] | None = None
    candidate_arm: ArmVector | None = None
    way: tuple[tuple[Finite, Finite], ...] = Field(default=(), max_length=MAX_WAY)
    plans: int = Field(ge=0)
    replans: int = Field(ge=0)
    stalls: int = Field(ge=0)
    error_norm: NonNegative | None = None
    reason: str = ""
    last_event: str = ""
    planning_ms: NonNegative | None = None
    refusals: int = Field(default=0, ge=0)
    last_refusal: str = ""
