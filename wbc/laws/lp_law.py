"""The parsimonious whole-body law: u from the linear program 5.29, one step at a time."""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from wbc.geometry.obstacles import Obstacle, split
from wbc.laws.constraints.arm_obstacles import ArmObstacles
from wbc.laws.constraints.base import Constraint
from wbc.laws.constraints.error_bound import ErrorBound
from wbc.laws.constraints.joint_limits import JointLimits
from wbc.laws.constraints.nonholonomic import Nonholonomic
from wbc.laws.constraints.obstacle_border import BorderObstacle
from wbc.laws.constraints.obstacle_conservative import ConservativeObstacle
from wbc.laws.constraints.obstacle_vector_field import VectorFieldObstacle
from wbc.laws.gains import composed, gain
from wbc.laws.law_output import LawOutput, summarise
from wbc.laws.linear_program import WarmStartedLP
from wbc.laws.objectives.base import ObjectiveTerm, ResidualCost
from wbc.laws.objectives.base_target import BaseTarget
from wbc.laws.objectives.input_change import InputChange
from wbc.laws.objectives.obstacle_circulation import ObstacleCirculation
from wbc.laws.objectives.velocity_cost import LeastVelocity
from wbc.laws.objectives.waist_centring import WaistCentring
from wbc.laws.objectives.waist_hold import WaistHold
from wbc.laws.step_context import StepContext
from wbc.robot import MobileManipulator
from wbc.task import PoseTask, Task, same_task
from wbc.validation import NonFiniteInputError, require_finite

Array = np.ndarray


CONSTRAINTS: tuple[type[Constraint], ...] = (
    Nonholonomic,
    JointLimits,
    ErrorBound,
    BorderObstacle,
    VectorFieldObstacle,
    ConservativeObstacle,
    ArmObstacles,
)
"""The constraints of 5.29, in the order of their rows; each builds itself from the gains it
declares (``of``), or stays out."""
OBJECTIVES: tuple[type[ObjectiveTerm], ...] = (
    LeastVelocity,
    WaistHold,
    WaistCentring,
    ObstacleCirculation,
    BaseTarget,
    InputChange,
)
"""The terms added to the task residual of 5.29, likewise."""


@dataclass(frozen=True)
class TaskGains:
    eta: float = gain(0.6, low=1e-3, high=100.0, doc="task gain: the LP seeks J u = -eta e, 1/s")


LPParams = composed(
    "LPParams",
    "Gains of the LP law, each declared by the term that reads it; the defaults are those of "
    "the pose experiment (section 6.2.1).",
    [TaskGains, *(part for term in CONSTRAINTS + OBJECTIVES for part in term.gains)],
    __name__,
)


def default_constraints(params: LPParams) -> list[Constraint]:
    """The constraints of 5.29 that ``params`` selects."""
    return [c for c in (term.of(params) for term in CONSTRAINTS) if c is not None]


def default_objectives(params: LPParams) -> list[ObjectiveTerm]:
    """The terms added to the task residual of 5.29 that ``params`` selects."""
    return [t for t in (term.of(params) for term in OBJECTIVES) if t is not None]


def program(
    robot: MobileManipulator,
    q: Array,
    task: Task,
    dt: float,
    obstacles: Sequence[Obstacle],
    eta: float,
    last: tuple[Task, Array] | None,
    constraints: Sequence[Constraint],
    objectives: Sequence[ObjectiveTerm],
    previous_u: Array | None = None,
) -> tuple[list, list, Array, tuple[Task, Array]]:
    """One step's program of 5.29: the inputs checked (``NonFiniteInputError``, dt > 0), e
    and e' measured (``error_rate``, against the ``last`` error if it was the same task's), the
    costs (the task's first, ||J u + eta e||) and the rows; with e and the new ``last``.
    ``obstacles`` mixes circles for the base and solids in 3-D (``wbc.geometry.obstacles.split``).
    ``previous_u`` is the u the law gave at its previous step, for the terms and rows that read
    it (``StepContext.previous_u``). The LP and the QP (``wbc.laws.qp_law``) solve the same one."""
    q, dt = np.asarray(q, dtype=float), float(dt)
    # One test for a good q and dt (the sum of the q_i is finite only if every q_i is, or
    # overflows: then ``_check`` looks entry by entry); ``_check`` names what is wrong.
    if q.ndim != 1 or not math.isfinite(sum(q.tolist())) or not 0.0 < dt < math.inf:
        _check(q, dt)
    circles, solids = _obstacles(obstacles) if obstacles else ((), ())
    chain = robot.forward(q)  # one pass for the task and the collision parts' rows
    error, task_jacobian = task.error(chain.pose, chain.jacobian, q)
    last_error = None
    if last is not None and (last[0] is task or same_task(last[0], task)):
        last_error = last[1]
    rate = error_rate(error, last_error, eta, dt)
    goal_pose = task.pose if isinstance(task, PoseTask) else None
    # The named tuple built by tuple.__new__: the same value, without its own __new__'s frame.
    context = tuple.__new__(
        StepContext,
        (
            robot,
            q,
            error,
            rate,
            task.goal_position[:2],
            circles,
            goal_pose,
            dt,
            solids,
            previous_u,
            chain,
        ),
    )
    costs, rows = terms(context, task_jacobian, eta, constraints, objectives)
    return costs, rows, error, (task, error)


def error_rate(error: Array, last_error: Array | None, eta: float, dt: float) -> Array:
    """e' = (e - e_last) / dt against the ``last_error`` of the same task, else (None) the
    commanded -eta e: what 5.10 bounds ||u||_1 by (beta ||e'||_1)."""
    if last_error is None:
        return -eta * error
    rate = np.subtract(error, last_error)
    # In place, by dt as a 0-d array: the same quotients, without NumPy's conversion of a
    # Python float at every step (half the time of ``/= dt``).
    np.divide(rate, _period(dt), rate)
    return rate


def terms(
    context: StepContext,
    task_jacobian: Array,
    eta: float,
    constraints: Sequence[Constraint],
    objectives: Sequence[ObjectiveTerm],
) -> tuple[list, list]:
    """The costs of 5.29 (the task's first, ||J u + eta e||, then the objective's terms) and
    the constraints' rows, at one step's ``context``."""
    rows = [constraint.rows(context) for constraint in constraints]  # first: a term may read
    costs = [ResidualCost("task", task_jacobian, eta * context.error)]  # what a row engaged
    costs += [term.cost(context) for term in objectives]
    return costs, rows


@functools.lru_cache(maxsize=4)
def _period(dt: float) -> Array:
    """dt as a read-only 0-d array, made once for the few periods a controller steps at."""
    period = np.array(dt)
    period.flags.writeable = False
    return period


def _check(q: Array, dt: float) -> None:
    """``NonFiniteInputError`` for a q or dt not finite, ValueError for dt <= 0."""
    require_finite("configuration q", q)
    if not math.isfinite(dt):
        raise NonFiniteInputError(f"dt must be finite, got {dt}")
    if dt <= 0.0:
        raise ValueError(f"dt must be > 0, got {dt}")


def _obstacles(obstacles: Sequence[Obstacle]) -> tuple[tuple, tuple]:
    """The circles and the solids among ``obstacles``, each circle's numbers checked (a solid
    checked its own when it was made)."""
    circles, solids = split(obstacles)
    for index, obstacle in enumerate(circles):
        require_finite(f"obstacle {index}", (obstacle.x, obstacle.y, obstacle.radius))
    return circles, solids


@dataclass
class LPLaw:
    """u = argmin ||J u + eta e||_1 subject to the constraints (5.29), solved by HiGHS simplex.

    ``step`` never raises for a solver failure: it returns u = 0 with HiGHS's status. Inputs
    that are not finite raise NonFiniteInputError before any solve. The law remembers the last
    error to measure e' = (e_k - e_{k-1}) / dt; on the first step of a task it uses the
    commanded rate e' = -eta e. It remembers the u it returned too (``StepContext.previous_u``,
    read by the input change term), zero before its first step (a robot no law has commanded
    yet stands still: its drivers stop it when commands stop), and keeps it across ``reset``:
    the robot does not stop because its task changed; ``stopped`` sets it to zero where a
    controller sent zero instead of the law's u (a stale state, no goal, a held output).
    """

    robot: MobileManipulator
    params: LPParams = field(default_factory=LPParams)
    constraints: list[Constraint] | None = None
    objectives: list[ObjectiveTerm] | None = None
    _lp: WarmStartedLP = field(default_factory=WarmStartedLP, init=False, repr=False)
    _last: tuple[Task, Array] | None = field(default=None, init=False, repr=False)
    _previous_u: Array = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.stopped()
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
        """Forget the previous error, basis and terms' state, as for a new task (not the
        previous u: the robot is still moving)."""
        self._last = None
        self._lp.reset()
        for term in self.objectives or ():
            term.reset()

    def stopped(self) -> None:
        """The robot was told to stand still: u_prev = 0."""
        self._previous_u = np.zeros(self.robot.dof)

    def step(
        self, q: Array, task: Task, dt: float, obstacles: Sequence[Obstacle] = ()
    ) -> LawOutput:
        """One control step at configuration q (8,) towards ``task``; dt in seconds."""
        start = time.perf_counter()
        if self.constraints is None:
            self.constraints = default_constraints(self.params)
        if self.objectives is None:
            self.objectives = default_objectives(self.params)
        costs, rows, error, self._last = program(
            self.robot,
            q,
            task,
            dt,
            obstacles,
            self.params.eta,
            self._last,
            self.constraints,
            self.objectives,
            self._previous_u,
        )
        solution = self._lp.solve(costs, rows)
        u, status, objective, active, magnitudes = solution
        output = summarise(u, status, objective, active, error, start, True, magnitudes)
        self._previous_u = output.u
        return output
