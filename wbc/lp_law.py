"""The parsimonious whole-body law: u from the linear program 5.29, one step at a time."""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from wbc.constraints.base import Constraint
from wbc.constraints.error_bound import ErrorBound, ErrorBoundMode
from wbc.constraints.joint_limits import JointLimits
from wbc.constraints.nonholonomic import Nonholonomic
from wbc.constraints.obstacle_border import BorderObstacle
from wbc.constraints.obstacle_conservative import ConservativeObstacle
from wbc.constraints.obstacle_vector_field import VectorFieldObstacle
from wbc.gains import check_gains, gain
from wbc.law_output import LawOutput, summarise
from wbc.linear_program import WarmStartedLP
from wbc.objectives.base import ObjectiveTerm, ResidualCost
from wbc.objectives.base_target import BaseTarget
from wbc.objectives.obstacle_circulation import ObstacleCirculation
from wbc.objectives.velocity_cost import LeastVelocity
from wbc.objectives.waist_centring import WaistCentring
from wbc.objectives.waist_hold import WaistHold
from wbc.obstacles import Circle
from wbc.robot import MobileManipulator
from wbc.step_context import StepContext
from wbc.task import PoseTask, Task, same_task
from wbc.validation import NonFiniteInputError, require_finite

Array = np.ndarray


@dataclass(frozen=True)
class LPParams:
    """Gains of the LP law; the defaults are those of the pose experiment (section 6.2.1)."""

    eta: float = gain(0.6, low=1e-3, high=100.0,
                      doc="task gain: the LP seeks J u = -eta e, 1/s")
    beta: float = gain(15.0, low=1e-3, high=1e3, doc="bound gain of 5.10 / 5.7")
    joint_gain: float = gain(1.0, low=1e-3, high=1e4, doc="k of 5.14, 1/s")
    safety_factor: float = gain(0.9, low=0.01, high=1.0, doc="beta_l of 5.14")
    error_bound: ErrorBoundMode = gain(
        "derivative", doc="5.10 (bound on ||e'||_1) or the original 5.7 (bound on ||e||_1)")
    obstacle_mode: Literal["border", "vector_field", "conservative", "off"] = gain(
        "border",
        doc="obstacle constraint: 5.28 (border), the vector-field inequality d' >= -eta_d d "
            "(vector_field, wbc.constraints.obstacle_vector_field), 5.19 (conservative) or none")
    obstacle_gain: float = gain(2.0, low=1e-3, high=100.0,
                                doc="lambda of 5.26 (border), eta_d (vector_field), gain on the "
                                    "clearance (conservative), 1/s")
    obstacle_margin: float = gain(0.05, low=0.0, high=1.0,
                                  doc="extra clearance round each obstacle and the base, m")
    obstacle_lookahead: float = gain(0.1, low=0.0, high=1.0,
                                     doc="d: the border constraint acts on the point d ahead "
                                         "of the wheel axle, m")
    obstacle_circulation: float = gain(0.2, low=0.0, high=1.0,
                                       doc="weight of going round an obstacle on the goal's "
                                           "side while its border is engaged "
                                           "(wbc.objectives.obstacle_circulation)")
    circulation_speed: float = gain(0.1, low=0.0, high=1.0,
                                    doc="the speed along the border that term asks for, m/s")
    velocity_cost: float = gain(1e-3, low=0.0, high=1.0,
                                doc="w of w ||u||_1, the tie-break between optimal vertices; "
                                    "0 with the other weights solves 5.29 exactly "
                                    "(wbc.objectives.velocity_cost)")
    waist_hold: float = gain(0.02, low=0.0, high=1.0,
                             doc="extra weight of |q1'|: the task's yaw goes to the base, the "
                                 "waist holds (wbc.objectives.waist_hold)")
    waist_centring: float = gain(0.0, low=0.0, high=1.0,
                                 doc="weight of |q1' + k q1|: the waist/base-yaw self-motion "
                                     "spent on a centred waist (wbc.objectives.waist_centring)")
    waist_gain: float = gain(1.0, low=1e-3, high=100.0, doc="k of the waist centring, 1/s")
    waist_fade: float = gain(0.05, low=0.0, high=10.0,
                             doc="||e||_1 below which the waist centring fades out (0: never)")
    base_target: float = gain(0.05, low=0.0, high=1.0,
                              doc="weight of turning the base towards where it should stand "
                                  "for a pose goal (wbc.objectives.base_target)")
    base_target_gain: float = gain(4.0, low=1e-3, high=100.0, doc="k of the base target, 1/s")
    base_target_reach: float = gain(0.36, low=0.0, high=5.0,
                                    doc="how far behind the goal, along the gripper's heading, "
                                        "the base should stand, m: the mean horizontal reach "
                                        "over the arm goals of `parsimony bench` (0.36 +- 0.08)")
    base_target_stop: float = gain(0.15, low=1e-3, high=5.0,
                                   doc="distance from the base target within which it is off "
                                       "(full weight at twice), m")
    base_target_on: float = gain(0.3, low=0.0, high=3.2,
                                 doc="heading error above which the base target starts a "
                                     "steering burst, rad (0: always on)")
    base_target_off: float = gain(0.05, low=0.0, high=3.2,
                                  doc="heading error below which a steering burst ends, rad")
    nonholonomic: bool = gain(True, doc="False models a holonomic base (section 6.3, test 1)")

    def __post_init__(self) -> None:
        check_gains(self)
        if self.base_target_on > 0.0 and not self.base_target_off < self.base_target_on:
            raise ValueError(f"LPParams.base_target_off must be below base_target_on "
                             f"({self.base_target_on}), got {self.base_target_off}")


def default_constraints(params: LPParams) -> list[Constraint]:
    """The constraints of 5.29 that ``params`` selects."""
    constraints: list[Constraint] = [
        JointLimits(params.joint_gain, params.safety_factor),
        ErrorBound(params.beta, params.error_bound),
    ]
    if params.nonholonomic:
        constraints.insert(0, Nonholonomic())
    if params.obstacle_mode == "border":
        constraints.append(
            BorderObstacle(params.obstacle_gain, params.obstacle_margin, params.obstacle_lookahead)
        )
    elif params.obstacle_mode == "vector_field":
        constraints.append(VectorFieldObstacle(params.obstacle_gain, params.obstacle_margin,
                                               params.obstacle_lookahead))
    elif params.obstacle_mode == "conservative":
        constraints.append(ConservativeObstacle(params.obstacle_gain, params.obstacle_margin))
    return constraints


def default_objectives(params: LPParams) -> list[ObjectiveTerm]:
    """The terms added to the task residual of 5.29 that ``params`` selects."""
    terms: list[ObjectiveTerm] = []
    if params.velocity_cost > 0.0:
        terms.append(LeastVelocity(params.velocity_cost))
    if params.waist_hold > 0.0:
        terms.append(WaistHold(params.waist_hold))
    if params.waist_centring > 0.0:
        terms.append(WaistCentring(params.waist_centring, params.waist_gain, params.waist_fade))
    if params.obstacle_mode in ("border", "vector_field") and params.obstacle_circulation > 0.0:
        terms.append(ObstacleCirculation(params.obstacle_circulation, params.circulation_speed,
                                         params.obstacle_margin, params.obstacle_lookahead))
    if params.base_target > 0.0:
        terms.append(BaseTarget(params.base_target, params.base_target_gain,
                                params.base_target_reach, params.base_target_stop,
                                params.base_target_on, params.base_target_off))  # fmt: skip
    return terms


@dataclass
class LPLaw:
    """u = argmin ||J u + eta e||_1 subject to the constraints (5.29), solved by HiGHS simplex.

    ``step`` never raises for a solver failure: it returns u = 0 with HiGHS's status. Inputs
    that are not finite raise NonFiniteInputError before any solve. The law remembers the last
    error to measure e' = (e_k - e_{k-1}) / dt; on the first step of a task it uses the
    commanded rate e' = -eta e.
    """

    robot: MobileManipulator
    params: LPParams = field(default_factory=LPParams)
    constraints: list[Constraint] | None = None
    objectives: list[ObjectiveTerm] | None = None
    _lp: WarmStartedLP = field(default_factory=WarmStartedLP, init=False, repr=False)
    _last: tuple[Task, Array] | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        self._explicit_constraints = self.constraints is not None
        self._explicit_objectives = self.objectives is not None

    def set_params(self, params: LPParams) -> None:
        """Change the gains between steps (the constraints are rebuilt from them)."""
        self.params = params
        if not self._explicit_constraints:
            self.constraints = None
        if not self._explicit_objectives:
            self.objectives = None

    def reset(self) -> None:
        """Forget the previous error, basis and terms' state, as for a new task."""
        self._last = None
        self._lp.reset()
        for term in self.objectives or ():
            term.reset()

    def step(
        self, q: Array, task: Task, dt: float, obstacles: Sequence[Circle] = ()
    ) -> LawOutput:
        """One control step at configuration q (8,) towards ``task``; dt in seconds."""
        start = time.perf_counter()
        q = require_finite("configuration q", q)
        dt = float(dt)
        if not math.isfinite(dt):
            raise NonFiniteInputError(f"dt must be finite, got {dt}")
        if dt <= 0.0:
            raise ValueError(f"dt must be > 0, got {dt}")
        for index, obstacle in enumerate(obstacles):
            require_finite(f"obstacle {index}", (obstacle.x, obstacle.y, obstacle.radius))
        if self.constraints is None:
            self.constraints = default_constraints(self.params)
        if self.objectives is None:
            self.objectives = default_objectives(self.params)

        pose, jacobian = self.robot.kinematics(q)
        error, task_jacobian = task.error(pose, jacobian, q)
        if self._last is not None and same_task(self._last[0], task):
            error_rate = (error - self._last[1]) / dt
        else:
            error_rate = -self.params.eta * error
        self._last = (task, error)

        goal_pose = task.pose if isinstance(task, PoseTask) else None
        context = StepContext(self.robot, q, error, error_rate, task.goal_position[:2],
                              tuple(obstacles), goal_pose, dt)  # fmt: skip
        rows = [constraint.rows(context) for constraint in self.constraints]
        costs = [ResidualCost("task", task_jacobian, self.params.eta * error)]
        costs += [term.cost(context) for term in self.objectives]
        solution = self._lp.solve(costs, rows)
        return summarise(
            solution.u, solution.status, solution.objective, solution.active, error, start
        )
