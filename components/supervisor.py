"""The staging supervisor: the operator's goal in, the controller's goal out, phase by phase.

It reads the goal the operator (or the state estimator, remapped) gives on ``goal/request``,
the robot state and the obstacles, and for a pose goal runs ``wbc.staging_supervisor``: it
plans where the base should stand and publishes on ``control/goal`` the task of each phase
(drive, turn, approach, then the pose task itself), with every robot state, so that the
controller, which alone commands the robot, steps the LP on it.

Plans run on a planner thread of their own, never on the handler thread that answers status
queries (a plan is bounded by ``wbc.staging.StagingParams.budget_s`` of CPU time, and a goal
too far or inside an obstacle is refused at once). While one runs, and once a goal is found
unreachable, the supervisor publishes a ``point`` goal that holds the base and arm where they
stood when it began, so the robot stops, and says why on ``supervisor/status``. A request
refused as malformed (a NaN, a pose that is not a unit dual quaternion...) leaves the current
goal as it is and is reported on the status with its reason (``refusals``, ``last_refusal``).
Position goals pass through unchanged. A goal moved by more than ``MEASUREMENT_TOLERANCE`` is
a new goal and is planned afresh; a restarted supervisor reports ``idle`` until a goal comes,
and plans again from where the robot is.
"""

from __future__ import annotations

import logging
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from components.controller import goal_of
from components.params import Param, ParamError, load_robot
from components.process_entry import run_component
from components.pubsub import Input
from components.runtime import Component, Node
from messages import topics
from messages.goal import Goal
from messages.obstacles import Obstacles, circles_of
from messages.state import RobotState
from messages.supervisor import SupervisorStatus
from wbc.drive_tasks import PointTask, offset_point
from wbc.obstacles import Circle
from wbc.staging import Plan
from wbc.staging_supervisor import PlanRequest, StagingSupervisor, SupervisorParams
from wbc.task import MEASUREMENT_TOLERANCE, PoseTask, Task, same_task

log = logging.getLogger("components.supervisor")

DEFAULTS = SupervisorParams()
COUNTED = {"plan": "plans", "replan": "replans", "stall": "stalls", "unreachable": "unreachable"}
"""The supervisor's events that are counted, and their counters."""


class Supervisor(Component):
    """goal/request + robot/state -> control/goal, supervisor/status."""

    reads = (Input(topics.GOAL_REQUEST), Input(topics.ROBOT_STATE), Input(topics.WORLD_OBSTACLES))
    writes = (topics.CONTROL_GOAL, topics.SUPERVISOR_STATUS)
    params = (
        Param("stall_window_s", float, DEFAULTS.stall_window_s, low=0.1, high=60.0,
              doc="a phase stalls when its error falls by less than stall_reduction over this"),
        Param("stall_reduction", float, DEFAULTS.stall_reduction, low=0.0, high=0.9,
              doc="share of the error a phase must shed per stall window"),
        Param("max_replans", int, DEFAULTS.max_replans, low=0, high=20,
              doc="re-plans after stalls before the goal is reported unreachable"),
        Param("pose_tolerance", float, 5e-3, low=1e-5, high=0.5,
              doc="||vec8(x - x_d)|| under which the pose goal counts as reached (looser "
                  "than the kinematic bench's: a measured pose jitters)"),
    )  # fmt: skip

    def __init__(self, node: Node) -> None:
        super().__init__(node)
        if node.profile.robot is None:
            raise ParamError("robot: the profile names no robot description")
        self.robot = load_robot(node.profile.robot)
        self.goal_out = node.publisher(topics.CONTROL_GOAL)
        self.status_out = node.publisher(topics.SUPERVISOR_STATUS)
        self.request: Goal | None = None
        self.supervisor: StagingSupervisor | None = None
        self.obstacles: tuple[Circle, ...] = ()
        self.planner = ThreadPoolExecutor(max_workers=1, thread_name_prefix="planner")
        self._planning: PlanRequest | None = None
        """The plan handed to the planner thread last."""
        self._t = 0.0
        """The stamp of the latest state, s."""
        self._events_reported = 0
        self._hold: PointTask | None = None
        """Where the robot stands still while a plan runs or after its goal was found
        unreachable."""
        self.last_refusal = ""
        for name in (*COUNTED.values(), "refusals"):
            node.counters[name] = 0
        node.subscribe(topics.GOAL_REQUEST, self.on_request, on_reject=self.on_refused)
        node.subscribe(topics.WORLD_OBSTACLES, self.on_obstacles)
        node.subscribe(topics.ROBOT_STATE, self.on_state)

    def on_obstacles(self, message: Obstacles) -> None:
        self.obstacles = circles_of(message)

    def on_request(self, goal: Goal) -> None:
        """A new goal replaces the supervisor; the same goal measured again keeps it."""
        if self.request is not None and goal.task == self.request.task == "pose":
            if same_task(PoseTask(np.array(self.request.pose)), PoseTask(np.array(goal.pose)),
                         MEASUREMENT_TOLERANCE):  # fmt: skip
                return
        self.request, self.supervisor, self._events_reported = goal, None, 0
        self._hold = self._planning = None

    def on_refused(self, reason: str) -> None:
        """A malformed request: counted, and said on the status at once."""
        self.node.count("refusals")
        self.last_refusal = reason
        self.status_out.put(self._status(self.node.clock.now_ns()))

    def on_state(self, state: RobotState) -> None:
        """Advance the phases and publish the controller's goal and the status."""
        request, stamp = self.request, state.header.stamp_ns
        if request is None:
            self.status_out.put(self._status(stamp))
            return
        if not state.valid:
            return
        if request.task != "pose":
            self.goal_out.put(request.model_copy(update={"header": self.node.header()}))
            return
        q = np.array(state.configuration())
        self._t = stamp / 1e9
        if self.supervisor is None:
            self.supervisor = StagingSupervisor(self.robot, np.array(request.pose),
                                                self.obstacles, self._params())  # fmt: skip
        supervisor = self.supervisor
        task = supervisor.update(q, self._t)
        if supervisor.pending is not None and supervisor.pending is not self._planning:
            self._planning, self._hold = supervisor.pending, None
            self.planner.submit(self._plan, supervisor, supervisor.pending)
        self._report_events(supervisor)
        if task is None:
            if self._hold is None:
                self._hold = PointTask(offset_point(q, DEFAULTS.lookahead), q[3:],
                                       DEFAULTS.lookahead)  # fmt: skip
            task = self._hold
        self.goal_out.put(self._goal_of(task, request, stamp))
        self.status_out.put(self._status(stamp))

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
        self.status_out.put(self._status(self.node.clock.now_ns()))

    def _params(self) -> SupervisorParams:
        p = self.node.params
        return SupervisorParams(stall_window_s=p["stall_window_s"],
                                stall_reduction=p["stall_reduction"],
                                max_replans=p["max_replans"],
                                pose_tolerance=p["pose_tolerance"])  # fmt: skip

    def _goal_of(self, task: Task, request: Goal, stamp_ns: int) -> Goal:
        """The controller's goal for ``task``: the operator's own for the pose task (with its
        gains), else the phase's."""
        header = self.node.header(stamp_ns=stamp_ns)
        if isinstance(task, PoseTask):
            return request.model_copy(update={"header": header})
        return goal_of(task, header)

    def _report_events(self, supervisor: StagingSupervisor) -> None:
        for event in supervisor.events[self._events_reported:]:
            counter = COUNTED.get(event.kind)
            if counter:
                self.node.count(counter)
            level = logging.WARNING if event.kind in ("stall", "unreachable") else logging.INFO
            log.log(level, "%s at %.2f s: %s", event.kind, event.t, event.detail)
        self._events_reported = len(supervisor.events)

    def _status(self, stamp_ns: int) -> SupervisorStatus:
        """What the supervisor does now: ``idle`` with no goal, else its phase."""
        header = self.node.header(stamp_ns=stamp_ns)
        refused = {"refusals": self.node.counters["refusals"], "last_refusal": self.last_refusal}
        supervisor = self.supervisor
        if supervisor is None:
            return SupervisorStatus(header=header, phase="idle", candidate=0, plans=0, replans=0,
                                    stalls=0, reason="no goal on goal/request yet",
                                    **refused)  # fmt: skip
        candidate = supervisor.candidate
        return SupervisorStatus(
            header=header,
            phase=supervisor.phase.value,
            candidate=len(supervisor.tried),
            candidate_base=None if candidate is None else tuple(candidate.base.tolist()),
            candidate_arm=None if candidate is None else tuple(candidate.arm.tolist()),
            way=tuple(tuple(point.tolist()) for point in supervisor.way()),
            plans=len(supervisor.planning_s),
            replans=supervisor.replans,
            stalls=sum(e.kind == "stall" for e in supervisor.events),
            reason=supervisor.reason,
            last_event=supervisor.events[-1].detail if supervisor.events else "",
            planning_ms=supervisor.planning_s[-1] * 1e3 if supervisor.planning_s else None,
            **refused,
        )

    def shutdown(self) -> None:
        """Drop a plan still waiting; one running ends with its budget."""
        self.planner.shutdown(wait=False, cancel_futures=True)


if __name__ == "__main__":
    run_component(Supervisor)
