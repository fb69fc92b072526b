"""What the staging supervisor is doing for the operator's goal."""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from messages.base import ArmVector, Finite, Message, NonNegative
from messages.header import Header
from messages.obstacles import MAX_CIRCLES
from wbc.planning.supervisor_phase import Phase

ENDED = ("refused", "aborted")
"""The phases of a goal the supervisor gave up on before the planner could: ``refused`` when
it came (no valid robot state, a target outside the camera's view), ``aborted`` while it ran
(the state went invalid). Like ``unreachable``, each stays until the next goal, the robot held
where it stands."""

IDLE = "idle"
"""The phase of a supervisor with no goal."""
PHASES = (IDLE, "direct", *ENDED, *(phase.value for phase in Phase))
PhaseName = Literal[PHASES]  # type: ignore[valid-type]
"""``idle`` before any goal; ``direct`` for a goal that is not a pose (a position...), passed
on to the controller as it is, then ``reached``; ``ENDED``; else one of
``wbc.planning.supervisor_phase.Phase`` for a pose goal."""

StateName = Literal["none", "valid", "degraded", "invalid"]
"""The robot state the supervisor has: ``none`` (none yet, or none for a while), ``valid``,
``degraded`` (valid, the base pose carried by odometry alone: the camera lost the base's
marker) or ``invalid`` (no fix: no goal is driven)."""

MAX_WAY = 8 * MAX_CIRCLES + 3
"""The most points a status's way may hold: a planned way passes each of at most
``MAX_CIRCLES`` discs once, on an arc drawn as at most 8 corners (``wbc.planning.drive_planner``'s
pieces of at most pi/4), between the point the base left its start for, the staging point and
the candidate's base."""


class SupervisorStatus(Message):
    """The phase of the current goal (``wbc.planning.staging_supervisor``), published as it changes,
    with every robot state that follows, and at least every ``STATUS_EVERY_S`` of the supervisor
    (components.supervisor) while no state comes.

    ``phase`` is a ``PhaseName``; ``candidate`` numbers the staging candidate being driven to
    (1 the best), ``candidate_base`` is its base pose (x, y, phi) and ``candidate_arm`` its arm
    joints (rad); ``way`` is where the base has still to pass, in order (x, y): the waypoints
    of its planned way from the current leg's (the staging point last) while it drives, then
    the candidate's base (empty with no candidate);
    ``plans``, ``replans`` and ``stalls`` count since the goal came; ``error_norm`` is ||e||
    of the goal's own task (the pose task's, a direct goal's) at the latest state;
    ``reason`` says why the phase is what it is where that is not plain (why a goal is
    unreachable, refused or aborted; why there is no goal);
    ``last_event`` is the latest thing the supervisor did, in words; ``planning_ms`` is the
    time of the last plan and ``planning_cpu_ms`` its planning thread's CPU time (the plan's
    budget is CPU time); ``refusals`` counts the requests refused since the supervisor
    started (malformed ones, which leave the current goal as it is, and goals refused),
    ``last_refusal`` says why the latest was; ``request_stamp_ns`` is the header stamp of the
    latest goal request taken (the one worked, or one that asked the same again; 0 before any),
    so that who sent a goal tells its statuses from those published before it was taken;
    ``state`` is a ``StateName``, since ``state_since_s`` (the stamp of the first state so, s);
    ``no_fix_s`` how long the camera has not fixed the base, s, when the state is degraded or
    invalid; ``warning`` what the operator should know that the phase does not say (the base
    out of the camera's sight).
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
    planning_cpu_ms: NonNegative | None = None
    refusals: int = Field(default=0, ge=0)
    last_refusal: str = ""
    request_stamp_ns: int = Field(default=0, ge=0)
    state: StateName = "valid"
    state_since_s: NonNegative | None = None
    no_fix_s: NonNegative | None = None
    warning: str = ""
