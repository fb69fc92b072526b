"""The staging supervisor: the operator's goal in, the controller's goal out, phase by phase.

It reads the goal the operator (or the state estimator, remapped) gives on ``goal/request``,
the robot state and the obstacles, and for a pose goal runs ``wbc.planning.staging_supervisor``: it
plans where the base should stand and publishes on ``control/goal`` the task of each phase
(drive, turn, approach, then the pose task itself), with every robot state, so that the
controller, which alone commands the robot, steps the LP on it. A goal of another kind (a
position...) passes through as it is (phase ``direct``) until its task's error is within
``pose_tolerance`` (``reached``).

Plans run on a planner thread of their own, never on the handler thread that answers status
queries (a whole plan, its way round the obstacles included, is bounded by
``planning_budget_s`` of CPU time, and a goal too far or inside an obstacle is refused at once).
With the profile's scene, a plan keeps the base where the scene's ceiling camera sees its
marker (``keep_in_view``), and a goal of another kind whose target lies out of that sight,
or farther than a plan may cover, is refused. While a plan runs, and once a goal is found
unreachable, refused or aborted, the supervisor publishes a ``point`` goal that holds the base
and arm where they stood, so the robot stops, and says why on ``supervisor/status``.

A goal is taken on the first robot state after it: without a valid one (no camera fix yet,
or no state for ``STATE_TIMEOUT_S``) it is refused, and a goal under way when the state goes
invalid is aborted (the robot does not drive off again on its own when a fix comes back; the
same goal sent again is taken anew). A state whose joints are not the robot description's is
refused (``refused_states``, one line naming the joints expected), and so is a goal whose arm
is not as many joints. A request refused as malformed (a NaN, a pose that is
not a unit dual quaternion...) leaves the current goal as it is and is reported on the status
with its reason (``refusals``, ``last_refusal``). A goal moved by more than
``MEASUREMENT_TOLERANCE`` is a new goal and is planned afresh; a restarted supervisor reports
``idle`` until a goal comes, and plans again from where the robot is. A status goes out with
every robot state, with every request refused, and every ``STATUS_EVERY_S`` while neither
comes.
"""

from __future__ import annotations

import logging
import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from components.control_step import task_of
from components.controller import goal_of
from components.direct_goal import direct_refusal
from components.joint_check import joints_match
from components.params import Param, ParamError, load_robot
from components.process_entry import run_component
from components.pubsub import Input, Subscription
from components.robot_sight import RobotSight
from components.runtime import Component, Node
from components.stop_latch import StopLatch
from components.supervisor_status import supervisor_status
from messages import topics
from messages.goal import Goal
from messages.obstacles import Obstacles, circles_of
from messages.state import RobotState
from messages.supervisor import ENDED, IDLE, SupervisorStatus
from messages.teleop import TeleopCommand
from wbc.geometry.obstacles import Circle
from wbc.planning.drive_tasks import PointTask, offset_point
from wbc.planning.staging import Plan, StagingParams
from wbc.planning.staging_supervisor import PlanRequest, StagingSupervisor, SupervisorParams
from wbc.planning.supervisor_phase import Phase
from wbc.task import MEASUREMENT_TOLERANCE, PoseTask, Task, same_task

log = logging.getLogger("components.supervisor")

DEFAULTS = SupervisorParams()
COUNTED = {"plan": "plans", "replan": "replans", "stall": "stalls", "unreachable": "unreachable"}
"""The supervisor's events that are counted, and their counters."""
STATUS_EVERY_S = 0.5
"""A status goes out at least this often (the profile's clock), states or none."""
STATE_TIMEOUT_S = 1.0
"""With no robot state for this long (the profile's clock) the supervisor has none."""


class Supervisor(Component):
    """goal/request + robot/state -> control/goal, supervisor/status."""

    reads = (Input(topics.GOAL_REQUEST), Input(topics.ROBOT_STATE), Input(topics.WORLD_OBSTACLES))
    writes = (topics.CONTROL_GOAL, topics.SUPERVISOR_STATUS)
    params = (
        Param(
            "stall_window_s",
            float,
            DEFAULTS.stall_window_s,
            low=0.1,
            high=60.0,
            doc="a phase stalls when its error falls by less than stall_reduction over this",
        ),
        Param(
            "stall_reduction",
            float,
            DEFAULTS.stall_reduction,
            low=0.0,
            high=0.9,
            doc="share of the error a phase must shed per stall window",
        ),
        Param(
            "max_replans",
            int,
            DEFAULTS.max_replans,
            low=0,
            high=20,
            doc="re-plans after stalls before the goal is reported unreachable",
        ),
        Param(
            "pose_tolerance",
            float,
            DEFAULTS.pose_tolerance,
            low=1e-5,
            high=0.5,
            doc="||e|| of the goal's task under which it counts as reached (||vec8(x - x_d)||"
            " for a pose: looser than the kinematic bench's, a measured pose jitters)",
        ),
        Param(
            "planning_budget_s",
            float,
            StagingParams.budget_s,
            low=0.05,
            high=30.0,
            doc="CPU seconds a plan may take, its way round the obstacles included",
        ),
        Param(
            "keep_in_view",
            bool,
            True,
            doc="plans keep the base where the scene's camera sees its marker, and goals "
            "out of its sight are refused (the scene's camera position and reference_pose "
            "must place the camera)",
        ),
    )

    def __init__(self, node: Node) -> None:
        super().__init__(node)
        if node.profile.robot is None:
            raise ParamError("robot: the profile names no robot description")
        self.robot = load_robot(node.profile.robot)
        self.goal_out = node.publisher(topics.CONTROL_GOAL)
        self.status_out = node.publisher(topics.SUPERVISOR_STATUS)
        self.sight = RobotSight(node.profile.scene, STATE_TIMEOUT_S)
        self.request: Goal | None = None
        self.fresh = False
        """The request has met no robot state yet: it is taken (or refused) on the next."""
        self.ended: tuple[str, str] | None = None
        """(``refused`` or ``aborted``, why) where the current request was given up."""
        self.reached = False
        """A direct goal's task was met."""
        self.error_norm: float | None = None
        self.supervisor: StagingSupervisor | None = None
        self.obstacles: tuple[Circle, ...] = ()
        self.planner = ThreadPoolExecutor(max_workers=1, thread_name_prefix="planner")
        self._planning: PlanRequest | None = None
        """The plan handed to the planner thread last."""
        self._t = 0.0
        """The stamp of the latest state, s."""
        self._events_reported = 0
        self._hold: PointTask | None = None
        """Where the robot stands still while a plan runs or after its goal was given up."""
        self._published = 0
        """Statuses published since the last tick of the status timer."""
        self.last_refusal = ""
        self.request_stamp_ns = 0
        """The header stamp of the latest goal request taken (``SupervisorStatus``)."""
        for name in (*COUNTED.values(), "refusals", "aborted", "refused_states"):
            node.counters[name] = 0
        self.latch = StopLatch(node)
        self.teleoperated = False
        """A hand commands the robot (``teleop/command``): no goal goes out until a new one."""
        self.teleop = Subscription(node, topics.TELEOP_COMMAND, self.on_teleop)  # a tool's
        node.subscribe(topics.GOAL_REQUEST, self.on_request, on_reject=self.on_refused)
        node.subscribe(topics.WORLD_OBSTACLES, self.on_obstacles)
        node.subscribe(topics.ROBOT_STATE, self.on_state)
        node.timer(STATUS_EVERY_S, self.on_tick)

    def on_obstacles(self, message: Obstacles) -> None:
        self.obstacles = circles_of(message)

    def on_request(self, goal: Goal) -> None:
        """A new goal replaces the current one, to be taken on the next state; the same goal
        measured again keeps it (unless it was given up)."""
        request = self.request
        self.request_stamp_ns = goal.header.stamp_ns
        if request is not None and self.ended is None and goal.task == request.task:
            if same_task(task_of(request), task_of(goal), MEASUREMENT_TOLERANCE):
                return
        self.request, self.fresh, self.ended, self.teleoperated = goal, True, None, False
        self.supervisor, self._events_reported, self.reached = None, 0, False
        self._hold = self._planning = None
        self.error_norm = None

    def on_teleop(self, _hand: TeleopCommand) -> None:
        """A hand takes the robot: the supervisor yields until a new goal."""
        self.teleoperated = True

    def on_refused(self, reason: str) -> None:
        """A malformed request: counted, and said on the status at once."""
        self.node.count("refusals")
        self.last_refusal = reason
        self._publish(self.node.clock.now_ns())

    def on_state(self, state: RobotState) -> None:
        """Take a new goal, advance the phases, publish the controller's goal and the status.
        A state whose joints are not the robot's is refused (``refused_states``)."""
        if self.latch.stopped or self.teleoperated:
            self._publish(state.header.stamp_ns)
            return  # the emergency stop: no phase advances, no goal goes out until the release
        names = self.robot.joint_names
        if not joints_match(self.node, "refused_states", "robot/state", state.joint_names, names):
            return
        stamp, request = state.header.stamp_ns, self.request
        self._t = stamp / 1e9
        self.sight.saw(state)
        if not state.valid:
            self._give_up(self.sight.missing(stamp))
        elif request is not None:
            q = np.array(state.configuration())
            if self.fresh:
                self._give_up(direct_refusal(request, q, self.robot, self._region()))
                self.fresh = False
            if self.ended is not None:
                self.goal_out.put(self._goal_of(self._held(q), request, stamp))
            else:
                pose, jacobian = self.robot.kinematics(q)
                error = float(np.linalg.norm(task_of(request).error(pose, jacobian, q)[0]))
                self.error_norm = error if math.isfinite(error) else None  # a goal at 1e300
                if request.task == "pose":
                    self.goal_out.put(self._goal_of(self._staged(request, q), request, stamp))
                else:
                    self._direct(request, stamp)
        self._publish(stamp)

    def on_tick(self) -> None:
        """Timer: a status when none went out since the last tick; a goal not taken yet
        refused when no state came for ``STATE_TIMEOUT_S`` (one under way is kept: the
        controller stops on a stale state, and the status says there is none)."""
        now = self.node.clock.now_ns()
        if self.fresh and self.sight.stale(now):
            self._give_up(self.sight.missing(now))
        if self._published == 0:
            self._publish(now)
        self._published = 0

    def _direct(self, request: Goal, stamp: int) -> None:
        """A goal of another kind than a pose: passed on, and reached once its error is within
        ``pose_tolerance``."""
        self.goal_out.put(request.model_copy(update={"header": self.node.header(stamp_ns=stamp)}))
        if (
            not self.reached
            and self.error_norm is not None
            and (self.error_norm < self.node.params["pose_tolerance"])
        ):
            self.reached = True
            log.info(
                "reached at %.2f s: %s goal, error %.3g", self._t, request.task, self.error_norm
            )

    def _staged(self, request: Goal, q: np.ndarray) -> Task:
        """The task of the pose goal's phase at q (a hold while it plans or once it is
        unreachable), its plan handed to the planner thread when one is due."""
        if self.supervisor is None:
            self.supervisor = StagingSupervisor(
                self.robot, np.array(request.pose), self.obstacles, self._params(), self._staging()
            )
        supervisor = self.supervisor
        task = supervisor.update(q, self._t)
        if supervisor.pending is not None and supervisor.pending is not self._planning:
            self._planning, self._hold = supervisor.pending, None
            self.planner.submit(self._plan, supervisor, supervisor.pending)
        self._report_events(supervisor)
        return task if task is not None else self._held(q)

    def _held(self, q: np.ndarray) -> PointTask:
        """The robot held where it stood when the hold began."""
        if self._hold is None:
            self._hold = PointTask(offset_point(q, DEFAULTS.lookahead), q[3:], DEFAULTS.lookahead)
        return self._hold

    def _give_up(self, reason: str) -> None:
        """Refuse the goal not taken yet, or abort the one under way, for ``reason`` (empty:
        neither)."""
        if not reason or self.request is None or self.ended is not None:
            return
        phase = "refused" if self.fresh else "aborted"
        self.ended, self.supervisor, self._planning = (phase, reason), None, None
        if self.fresh:
            self.node.count("refusals")
            self.last_refusal = reason
        else:
            self.node.count("aborted")
        self.node.warn(phase, f"goal {phase} at {self._t:.2f} s: {reason}")

    def _plan(self, supervisor: StagingSupervisor, request: PlanRequest) -> None:
        """Planner thread: run the plan, hand it to the handler thread."""
        try:
            found = request.run()
        except Exception as error:  # a bug in the planner must not leave the robot held mute
            log.exception("planning failed")
            found = Plan((), f"planning failed: {error}", 0.0)
        self.node.post(lambda: self._planned(supervisor, request, found))

    def _planned(self, supervisor: StagingSupervisor, request: PlanRequest, found: Plan) -> None:
        """Handler thread: a plan came back; a newer goal's supervisor ignores an old plan."""
        if supervisor is not self.supervisor or supervisor.pending is not request:
            return
        supervisor.take(found, self._t)
        self._report_events(supervisor)
        self._publish(self.node.clock.now_ns())

    def _params(self) -> SupervisorParams:
        p = self.node.params
        return SupervisorParams(
            stall_window_s=p["stall_window_s"],
            stall_reduction=p["stall_reduction"],
            max_replans=p["max_replans"],
            pose_tolerance=p["pose_tolerance"],
        )

    def _staging(self) -> StagingParams:
        return StagingParams(budget_s=self.node.params["planning_budget_s"], region=self._region())

    def _region(self) -> tuple[tuple[float, float, float], ...]:
        return self.sight.region if self.node.params["keep_in_view"] else ()

    def _goal_of(self, task: Task, request: Goal, stamp_ns: int) -> Goal:
        """The controller's goal for ``task``: the operator's own for the pose task (with its
        gains), else the phase's."""
        header = self.node.header(stamp_ns=stamp_ns)
        if isinstance(task, PoseTask):
            return request.model_copy(update={"header": header})
        return goal_of(task, header)

    def _report_events(self, supervisor: StagingSupervisor) -> None:
        for event in supervisor.events[self._events_reported :]:
            counter = COUNTED.get(event.kind)
            if counter:
                self.node.count(counter)
            level = logging.WARNING if event.kind in ("stall", "unreachable") else logging.INFO
            log.log(level, "%s at %.2f s: %s", event.kind, event.t, event.detail)
        self._events_reported = len(supervisor.events)

    def _publish(self, stamp_ns: int) -> None:
        status = self._status(stamp_ns)
        self.status_out.put(status)
        self._published += 1
        final = status.phase in (Phase.UNREACHABLE, *ENDED)
        self.node.state = f"{status.phase}: {status.reason}" if final else status.phase

    def _status(self, stamp_ns: int) -> SupervisorStatus:
        """What the supervisor does now: ``idle`` with no goal, else the goal's phase."""
        request, supervisor = self.request, self.supervisor
        if request is None:
            phase = IDLE
            reason = self.sight.missing(stamp_ns) or "no goal on goal/request yet"
        elif self.ended is not None:
            phase, reason = self.ended
        elif request.task != "pose":
            phase, reason = ("reached" if self.reached else "direct"), ""
        elif supervisor is None:
            phase, reason = "planning", ""
        else:
            phase, reason = supervisor.phase.value, supervisor.reason
        fields = dict(
            header=self.node.header(stamp_ns=stamp_ns),
            phase=phase,
            reason=reason,
            error_norm=self.error_norm,
            refusals=self.node.counters["refusals"],
            last_refusal=self.last_refusal,
            request_stamp_ns=self.request_stamp_ns,
            **self.sight.fields(stamp_ns),
        )
        return supervisor_status(supervisor, **fields)

    def shutdown(self) -> None:
        """Drop a plan still waiting; one running ends with its budget."""
        self.planner.shutdown(wait=False, cancel_futures=True)


if __name__ == "__main__":
    run_component(Supervisor)
