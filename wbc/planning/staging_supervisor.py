"""Above the local law: drive to a staging candidate by LP sub-tasks, then run the pose task.

For a pose goal x_d the supervisor takes the best candidate q_c of wbc.planning.staging and hands
the law one task per phase, every command still one LP step:

    planning  no task: the caller holds the robot while the plan of ``pending`` runs, on
              any thread (``PlanRequest.run``), and hands it back (``take``)
    drive     legs along the candidate's way round the obstacles (wbc.planning.drive_planner),
              waypoint by waypoint, the last to the staging point (a final leg behind q_c's
              base on its heading, or ahead of it), the arm going to q_c's: each leg a
              PointTask of the point d ahead of the axle, after a HeadingTask that turns the
              base to face the waypoint where it stands if it faces more than ``face_turn``
              away (so the base keeps to the way instead of curving off it)
    turn      HeadingTask: the base to q_c's heading where it stands, the arm held at q_c's
    approach  PointTask: the straight final leg to q_c's base
    align     HeadingTask: the base turned to q_c's heading again, the arm held: a point task
              leaves the heading free, and a leg that corrects a sideways offset ends turned
    pose      PoseTask(x_d): the ordinary LP pose task, which starts with room on every joint

A phase ends when its error is within its tolerance (a drive leg before the last, when its
point passes within ``waypoint_tolerance`` of its waypoint); phases already met are skipped;
a candidate the base stood near is approached straight. A phase (or leg) stalls when ||e||
falls by less than ``stall_reduction`` of itself over ``stall_window_s``: the supervisor then
re-plans from where the robot is, with the best candidate not yet tried, at most
``max_replans`` times; after that, or when no candidate exists, the goal is unreachable, the
reason is kept, and the supervisor gives no task (the robot stops).
``step`` plans in line, for a caller with no other thread (the kinematic loop).
"""

from __future__ import annotations

import collections
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from wbc.geometry.obstacles import Circle
from wbc.planar import wrap
from wbc.planning.candidate import Candidate, same_configuration, same_kind
from wbc.planning.drive_tasks import HeadingTask, PointTask
from wbc.planning.staging import Plan, StagingParams, plan
from wbc.planning.supervisor_phase import Phase
from wbc.robot import MobileManipulator
from wbc.task import PoseTask, Task

Array = np.ndarray


@dataclass(frozen=True)
class SupervisorParams:
    lookahead: float = 0.03
    """d: the drive legs steer the point this far ahead of the axle, m. Turning in place
    moves that point by up to 2 d sideways, which the approach must take out by steering and
    ends turned by; the smaller d, the straighter the base stands at its candidate (0.1 m
    reached 0.7 of the goals 'anywhere', 0.05 m 0.9 and 0.03 m 0.95, on 40 goals)."""
    leg_tolerance: float = 0.03
    """The drive ends with its point this close to the staging point's, m."""
    waypoint_tolerance: float = 0.1
    """A drive leg before the last ends with its point this close to its waypoint, m: the
    base turns towards the next one without slowing to a stop."""
    face_turn: float = math.pi / 3
    """A drive leg starts by turning the base in place to face its waypoint when it faces
    further away than this, rad (above the way's corners, at most pi/4)."""
    face_tolerance: float = 0.3
    """That turn ends with the base facing its waypoint this closely, rad: the leg's point
    task steers out the rest as it drives (the turn's last tenths of a radian, at the task
    gain's exponential rate, took seconds)."""
    approach_tolerance: float = 0.005
    """The approach ends with its point this close to the candidate's, m."""
    turn_tolerance: float = 0.05
    """The turn ends with the heading this close, rad."""
    align_tolerance: float = 0.01
    """The alignment ends with the heading this close, rad."""
    arm_tolerance: float = 0.01
    """The approach ends with every arm joint this close to the candidate's, rad."""
    pose_tolerance: float = 5e-3
    """The goal is reached when ||vec8(x - x_d)|| is below this: the running supervisor's
    default (``components.supervisor``), looser than a kinematic run's 1e-3 as a measured pose
    jitters; a kinematic run passes its own (``goal_sets.TOLERANCE``)."""
    stall_window_s: float = 2.0
    stall_reduction: float = 0.03
    max_replans: int = 3


@dataclass(frozen=True)
class Event:
    """Something the supervisor did, for its diagnostics."""

    t: float
    kind: str
    """'plan', 'phase', 'stall', 'replan', 'reached' or 'unreachable'."""
    detail: str


@dataclass(frozen=True)
class PlanRequest:
    """A plan the supervisor waits for, from configuration ``q`` at time ``t``: everything it
    needs is frozen here, so ``run`` may go on another thread while the caller holds."""

    robot: MobileManipulator
    q: Array
    goal_pose: Array
    obstacles: tuple[Circle, ...]
    staging: StagingParams
    t: float

    def run(self) -> Plan:
        return plan(self.robot, self.q, self.goal_pose, self.obstacles, self.staging)


@dataclass
class StagingSupervisor:
    """The phases of the module docstring for one goal; ``update`` once per control step."""

    robot: MobileManipulator
    goal_pose: Array
    obstacles: Sequence[Circle] = ()
    params: SupervisorParams = field(default_factory=SupervisorParams)
    staging: StagingParams = field(default_factory=StagingParams)
    phase: Phase = field(default=Phase.PLANNING, init=False)
    candidate: Candidate | None = field(default=None, init=False)
    replans: int = field(default=0, init=False)
    reason: str = field(default="", init=False)
    events: list[Event] = field(default_factory=list, init=False)
    planning_s: list[float] = field(default_factory=list, init=False)
    """How long each plan took, s (wall clock)."""
    planning_cpu_s: list[float] = field(default_factory=list, init=False)
    """The CPU time of each plan's thread, s."""
    tried: list[Candidate] = field(default_factory=list, init=False)
    """The candidates driven to so far, the current one last."""
    pending: PlanRequest | None = field(default=None, init=False)
    """The plan to run and ``take`` while the phase is PLANNING."""
    leg: int = field(default=0, init=False)
    """The drive's leg: the index of its waypoint in the candidate's way."""
    facing: bool = field(default=False, init=False)
    """The drive's leg turns to face its waypoint before it drives there."""
    _task: Task | None = field(default=None, init=False)
    _history: collections.deque = field(default_factory=collections.deque, init=False)
    _pose_task: PoseTask = field(init=False)

    def __post_init__(self) -> None:
        self._pose_task = PoseTask(np.asarray(self.goal_pose, dtype=float))

    @property
    def reached(self) -> bool:
        return self.phase is Phase.REACHED

    def way(self) -> tuple[Array, ...]:
        """Where the base has still to pass, in order, (x, y) each: while it drives, the
        waypoints of its way from the current leg's (the staging point last), then the
        candidate's base; the candidate's base while it turns and approaches; nothing before
        a candidate or once the base stands at it."""
        candidate = self.candidate
        if candidate is None or self.phase not in (Phase.DRIVE, Phase.TURN, Phase.APPROACH):
            return ()
        base = np.array(candidate.base[:2])
        if self.phase is Phase.DRIVE and candidate.way is not None:
            return (*candidate.way.waypoints[self.leg :], base)
        return (base,)

    def update(self, q: Array, t: float) -> Task | None:
        """Advance the phases at configuration q and time t (s); the task to step now, None
        while planning (the caller holds the robot) or once the goal is unreachable."""
        if self.phase is Phase.PLANNING:
            if self.pending is None:
                self.pending = PlanRequest(
                    self.robot,
                    np.array(q, dtype=float),
                    self._pose_task.pose,
                    tuple(self.obstacles),
                    self.staging,
                    t,
                )
            return None
        for _ in range(len(Phase)):
            if self._task is None:
                return None
            error = self._error(q)
            if self.phase is Phase.REACHED or not self._met(error):
                break
            self._advance(q, t)
        norm = float(np.linalg.norm(error))
        if self.phase is not Phase.REACHED and self._stalled(t, norm):
            self.events.append(Event(t, "stall", f"{self.phase} error {norm:.3g}"))
            self._replan(q, t)
        return self._task

    def step(self, q: Array, t: float) -> Task | None:
        """``update``, with any plan it asks for run in line."""
        task = self.update(q, t)
        if self.pending is not None:
            self.take(self.pending.run(), t)
            task = self.update(q, t)
        return task

    def take(self, found: Plan, t: float) -> None:
        """The plan of ``pending``: drive to its best candidate not tried yet, or give up."""
        request, self.pending = self.pending, None
        if request is None or self.phase is not Phase.PLANNING:
            return
        self.planning_s.append(found.elapsed_s)
        self.planning_cpu_s.append(found.cpu_s)
        fresh = [
            c for c in found.candidates if not any(same_configuration(c.q, o.q) for o in self.tried)
        ]
        # After a stall, another kind of configuration first: the neighbours of one that
        # stalled stall alike (same base within 0.1 m and 0.3 rad).
        fresh.sort(key=lambda c: any(same_kind(c.q, o.q) for o in self.tried))
        if not fresh:
            self._give_up(t, found.reason or "every staging candidate was tried")
            return
        self.candidate = fresh[0]
        self.tried.append(fresh[0])
        base = ", ".join(f"{v:.2f}" for v in fresh[0].base)
        self.events.append(
            Event(
                t,
                "plan",
                f"candidate {len(self.tried)} of "
                f"{len(found.candidates)}: base ({base}) score "
                f"{fresh[0].score:.2f} sigma {fresh[0].sigma:.3f}",
            )
        )
        self._enter(Phase.APPROACH if fresh[0].way is None else Phase.DRIVE, request.q, t)

    def _replan(self, q: Array, t: float) -> None:
        if self.replans >= self.params.max_replans:
            self._give_up(t, f"stalled in {self.phase} after {self.replans} re-plans")
            return
        self.replans += 1
        self.events.append(Event(t, "replan", f"re-plan {self.replans}"))
        self.phase, self._task = Phase.PLANNING, None
        self.update(q, t)

    def _give_up(self, t: float, reason: str) -> None:
        self.reason = reason
        self.phase, self._task = Phase.UNREACHABLE, None
        self.events.append(Event(t, "unreachable", reason))

    def _advance(self, q: Array, t: float) -> None:
        """Drive to the leg's waypoint once facing it, or drive the next leg of the way, or
        enter the phase declared after this one (``Phase`` lists them in order)."""
        if self.phase is Phase.DRIVE and (self.facing or not self._last_leg):
            self.leg += 0 if self.facing else 1
            self._drive(q, t, turn_first=not self.facing)
            return
        order = list(Phase)
        self._enter(order[order.index(self.phase) + 1], q, t)

    @property
    def _last_leg(self) -> bool:
        way = self.candidate.way if self.candidate is not None else None
        return way is None or self.leg >= len(way.waypoints) - 1

    def _drive(self, q: Array, t: float, turn_first: bool = True) -> None:
        """The task of the current leg: the turn to face its waypoint (``face_turn``), then
        the point task to it; for the last leg, to the staging point, the point d ahead of it
        on the candidate's heading."""
        candidate, d = self.candidate, self.params.lookahead
        assert candidate is not None and candidate.way is not None
        self._history.clear()
        if self._last_leg:
            phi = candidate.base[2]
            point = candidate.staging + d * np.array([math.cos(phi), math.sin(phi)])
        else:
            point = candidate.way.waypoints[self.leg]
        bearing = math.atan2(point[1] - q[1], point[0] - q[0])
        self.facing = turn_first and abs(wrap(bearing - q[2])) > self.params.face_turn
        if self.facing:
            self._task = HeadingTask(bearing, candidate.arm, np.array(q[:2], dtype=float))
        else:
            self._task = PointTask(point, candidate.arm, d)
        legs = len(candidate.way.waypoints)
        self.events.append(
            Event(
                t,
                "phase",
                f"drive, leg {self.leg + 1} of {legs}" + (", facing it" if self.facing else ""),
            )
        )

    def _enter(self, phase: Phase, q: Array, t: float) -> None:
        self.phase = phase
        self._history.clear()
        candidate, d = self.candidate, self.params.lookahead
        assert candidate is not None
        x, y, phi = candidate.base
        heading = np.array([math.cos(phi), math.sin(phi)])
        if phase is Phase.DRIVE:
            self.leg = 0
            self._drive(q, t)
            return
        self.facing = False
        if phase is Phase.TURN:
            self._task = HeadingTask(float(phi), candidate.arm, candidate.staging)
        elif phase is Phase.APPROACH:
            self._task = PointTask(np.array([x, y]) + d * heading, candidate.arm, d)
        elif phase is Phase.ALIGN:
            self._task = HeadingTask(float(phi), candidate.arm, np.array([x, y]))
        elif phase is Phase.POSE:
            self._task = self._pose_task
        else:
            self.events.append(Event(t, "reached", "pose goal reached"))
            return
        self.events.append(Event(t, "phase", str(phase)))

    def _error(self, q: Array) -> Array:
        pose, jacobian = self.robot.kinematics(q)
        assert self._task is not None
        return self._task.error(pose, jacobian, q)[0]

    def _met(self, error: Array) -> bool:
        p = self.params
        if self.phase is Phase.DRIVE and self.facing:
            return bool(abs(error[0]) < p.face_tolerance)
        if self.phase is Phase.DRIVE:
            tolerance = p.leg_tolerance if self._last_leg else p.waypoint_tolerance
            return bool(np.linalg.norm(error[:2]) < tolerance)
        if self.phase is Phase.TURN:
            return bool(abs(error[0]) < p.turn_tolerance)
        if self.phase is Phase.APPROACH:
            return bool(
                np.linalg.norm(error[:2]) < p.approach_tolerance
                and np.max(np.abs(error[2:])) < p.arm_tolerance
            )
        if self.phase is Phase.ALIGN:
            return bool(abs(error[0]) < p.align_tolerance)
        if self.phase is Phase.POSE:
            return bool(np.linalg.norm(error) < p.pose_tolerance)
        return False

    def _stalled(self, t: float, norm: float) -> bool:
        """||e|| fell by less than stall_reduction of itself over the last stall window."""
        history = self._history
        history.append((t, norm))
        window = self.params.stall_window_s
        if t - history[0][0] < window:
            return False
        while len(history) > 1 and t - history[1][0] >= window:
            history.popleft()
        return norm > (1.0 - self.params.stall_reduction) * history[0][1]
