"""The share of random pose goals (``studies.goal_families``) a law reaches inside the
robot's limits, and how parsimonious its u is on the way.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from studies.gain_sets import bare_5_29, input_change_gains, supervised_params
from wbc import dq
from wbc.geometry.obstacles import Circle, least_clearance
from wbc.geometry.scenarios import DT
from wbc.laws.cascade_law import CascadeLaw
from wbc.laws.kinematic_run import ControlEffort, control_effort, integrate, integrate_supervised
from wbc.laws.law_output import Law, entry_mask
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.laws.qp_law import QPLaw
from wbc.planning.staging_supervisor import StagingSupervisor, SupervisorParams
from wbc.robot import BASE_DOF, MobileManipulator
from wbc.task import PoseTask, PositionTask, Task

Array = np.ndarray

TIME_LIMIT_S = 60.0
TOLERANCE = 1e-3
LIMIT_TOLERANCE = 1e-6
MOVING_ERROR = 0.05
"""||e|| above which a step of a pose run counts as moving (figure 6.7's first part)."""
SETTLING_S = 2.0
"""The last seconds before convergence (figure 6.7's part after the 150th iteration)."""


@dataclass(frozen=True)
class Attempt:
    """One closed-loop run towards one goal."""

    converged: bool
    steps: int
    joint_overrun: float
    """Largest excursion of a joint beyond [q_min, q_max] (rad, 0 inside)."""
    speed_overrun: float
    """Largest |u_i| beyond the speed bound velocity_max_i (0 inside)."""
    nonzero: tuple[int, ...]
    """Which entries of u were nonzero at every step of the goal's own task (the pose task,
    or the position task; a supervisor's drive legs left out): bit i for u_i."""
    practical: tuple[int, ...]
    """The same for entries at or above Upsilon = 0.01 (section 6.2.1)."""
    errors: tuple[float, ...]
    """||e|| at those steps."""
    planning_s: tuple[float, ...] = ()
    """How long each staging plan took (supervised runs only), s."""
    planning_cpu_s: tuple[float, ...] = ()
    """The CPU time of each staging plan, s."""
    every_step_optimal: bool = True
    """Every command was an optimal solution of its step's program."""
    effort: ControlEffort | None = None
    """Table 6.1's metrics of the run's commands, from the first (as table 6.1 takes them)."""
    effort_from_rest: ControlEffort | None = None
    """The same with u = 0 before the first command: the jump from rest counts."""
    reason: str = ""
    """Why the goal was not reached: the supervisor's reason, or the time limit and the phase
    it ran out in; alone, the time limit and the joints then at or past the edge of the law's
    joint box (``at_joint_box_edge``); empty when reached."""
    clearance: float = math.inf
    """The least distance between the base's body and an obstacle over the run, m (below 0 is
    a contact); inf with no obstacle."""
    last: Array | None = None
    """The configuration the run ended in."""

    @property
    def seconds(self) -> float:
        """Time the run took, s: to convergence when it converged."""
        return self.steps * DT

    @property
    def within_joint_limits(self) -> bool:
        return self.converged and self.joint_overrun <= LIMIT_TOLERANCE

    @property
    def within_all_limits(self) -> bool:
        return self.within_joint_limits and self.speed_overrun <= LIMIT_TOLERANCE


def attempt(
    law: Law,
    robot: MobileManipulator,
    start: Array,
    goal: Array,
    supervised: bool = False,
    position: bool = False,
    obstacles: Sequence[Circle] = (),
) -> Attempt:
    """Run ``law`` from ``start`` to the pose of ``goal`` (or its position) for at most
    TIME_LIMIT_S, alone or with the staging supervisor handing it its tasks, with the
    obstacle constraint on ``obstacles``."""
    steps = int(TIME_LIMIT_S / DT)
    planning: tuple[float, ...] = ()
    planning_cpu: tuple[float, ...] = ()
    if supervised:
        params = SupervisorParams(pose_tolerance=TOLERANCE)
        supervisor = StagingSupervisor(robot, robot.fkm(goal), obstacles, params=params)
        tasks: list[object] = []
        run = integrate_supervised(law, _logged(supervisor, tasks), start, DT, steps, obstacles)
        own = [isinstance(task, PoseTask) for task in tasks[: len(run.outputs)]]
        planning = tuple(supervisor.planning_s)
        planning_cpu = tuple(supervisor.planning_cpu_s)
        reason = supervisor.reason or f"time limit in {supervisor.phase}"
    else:
        task = (
            PositionTask(dq.translation(robot.fkm(goal))[1:])
            if position
            else PoseTask(robot.fkm(goal))
        )
        run = integrate(law, start, task, DT, steps, TOLERANCE, obstacles)
        own = [True] * len(run.outputs)
        edge = at_joint_box_edge(law, robot, run.configurations[-1])
        reason = f"time limit, {' and '.join(edge) or 'no joint'} at the joint box's edge"
    q = np.array([start, *run.configurations])  # a supervisor may stop before any step
    u = np.vstack((np.zeros(robot.dof), run.velocities().reshape(-1, robot.dof)))
    joint_overrun = np.maximum(q - robot.q_max, robot.q_min - q).max()
    speed_overrun = (np.abs(u) - robot.velocity_max).max()
    outputs = [out for out, mine in zip(run.outputs, own, strict=True) if mine]
    return Attempt(
        run.converged,
        len(run.outputs),
        float(max(joint_overrun, 0.0)),
        float(max(speed_overrun, 0.0)),
        tuple(entry_mask(out.u) for out in outputs),
        tuple(entry_mask(out.u, True) for out in outputs),
        tuple(out.error_norm for out in outputs),
        planning,
        planning_cpu,
        all(out.ok for out in run.outputs),
        control_effort(run),
        control_effort(run, from_rest=True),
        "" if run.converged else reason,
        least_clearance(q[:, :2], obstacles, robot.base.body_radius),
        q[-1],
    )


EDGE = 0.01
"""How near the edge of its law's joint box (rad) a joint counts as at it."""


def at_joint_box_edge(law: Law, robot: MobileManipulator, q: Array) -> list[str]:
    """The arm joints of ``q`` (by the robot's names) within EDGE of the joint box of ``law``:
    b_l [q-, q+] for the LP and the QP (their safety factor b_l), the joint limits for a law
    without one (``MobileManipulator.joint_box``)."""
    factor = law.params.safety_factor if isinstance(law, LPLaw | QPLaw) else 1.0
    arm = q[BASE_DOF:]
    low, high = robot.joint_box(factor)
    near = np.minimum(arm - low[BASE_DOF:], high[BASE_DOF:] - arm) < EDGE
    return [robot.joint_names[index] for index in np.flatnonzero(near)]


def _logged(supervisor: StagingSupervisor, tasks: list[object]) -> StagingSupervisor:
    """``supervisor`` noting the task of every step in ``tasks``."""
    step = supervisor.step

    def noted(q: Array, t: float) -> Task | None:
        task = step(q, t)
        tasks.append(task)
        return task

    supervisor.step = noted  # type: ignore[method-assign]
    return supervisor


def shares(attempts: Iterable[Attempt]) -> dict[str, float]:
    """Share of goals reached: at all, inside the joint limits, inside joint and speed limits;
    and the median time to converge of the goals reached (s)."""
    attempts = list(attempts)
    count = max(len(attempts), 1)
    times = [a.seconds for a in attempts if a.converged]
    return {
        "reached": sum(a.converged for a in attempts) / count,
        "within_joint_limits": sum(a.within_joint_limits for a in attempts) / count,
        "within_joint_and_speed_limits": sum(a.within_all_limits for a in attempts) / count,
        "median_time_to_converge_s": float(np.median(times)) if times else math.nan,
        "every_step_optimal": sum(a.every_step_optimal for a in attempts) / count,
    }


def planning(attempts: Iterable[Attempt]) -> dict[str, float]:
    """Plans per run (mean) and the time of one plan (median, p99, ms): on the clock, and the
    planning thread's CPU time (what the plan itself cost, whatever else the machine ran)."""
    attempts = list(attempts)
    times = np.array([t for a in attempts for t in a.planning_s]) * 1e3
    cpu = np.array([t for a in attempts for t in a.planning_cpu_s]) * 1e3

    def percentile(values: Array, q: float) -> float:
        return float(np.percentile(values, q)) if values.size else math.nan

    return {
        "plans_per_run": len(times) / max(len(attempts), 1),
        "plan_median_ms": percentile(times, 50),
        "plan_p99_ms": percentile(times, 99),
        "plan_cpu_median_ms": percentile(cpu, 50),
        "plan_cpu_p99_ms": percentile(cpu, 99),
    }


def parsimony(attempts: Iterable[Attempt], dof: int) -> dict:
    """Nonzero entries of u: the exact and the practical (Upsilon) histograms over every step
    of the goal's task; the median while ||e|| > MOVING_ERROR and over the last SETTLING_S of
    the runs that converged; and the same median with x' and y' counted as one entry where
    both are nonzero (the base's forward speed v, which 5.11 splits between them)."""
    attempts = list(attempts)
    exact = [m for a in attempts for m in a.nonzero]
    settling = round(SETTLING_S / DT)
    moving = [
        m for a in attempts for m, e in zip(a.nonzero, a.errors, strict=True) if e > MOVING_ERROR
    ]
    last = [m for a in attempts if a.converged for m in a.nonzero[-settling:]]

    def median(masks: list[int], forward_as_one: bool = False) -> float:
        counts = [m.bit_count() - (forward_as_one and m & 3 == 3) for m in masks]
        return float(np.median(counts)) if counts else math.nan

    return {
        "nonzero_histogram": histogram(exact, dof),
        "practical_histogram": histogram([m for a in attempts for m in a.practical], dof),
        "median_nonzero_moving": median(moving),
        "median_nonzero_settling": median(last),
        "median_nonzero_settling_forward_as_one": median(last, True),
    }


def histogram(masks: list[int], dof: int) -> list[int]:
    """How many steps had 0, 1, ..., dof nonzero entries."""
    return np.bincount([m.bit_count() for m in masks], minlength=dof + 1).tolist()


def exact_5_29() -> LPParams:
    """5.29 as written, with the default law's eta, beta, k and b_l: no term beside the task,
    5.28 on the axle centre with 5.10 (``studies.gain_sets.bare_5_29``)."""
    return bare_5_29(LPParams())


SUPERVISED = "lp + staging supervisor"
LAWS: dict[str, Callable[[MobileManipulator], Law]] = {
    "lp": lambda robot: LPLaw(robot),
    "lp 5.29 exactly": lambda robot: LPLaw(robot, exact_5_29()),
    SUPERVISED: lambda robot: LPLaw(robot, supervised_params()),
    "qp": lambda robot: QPLaw(robot),
    "cascade": lambda robot: CascadeLaw(robot),
}
"""The laws compared: the default LP, LP 5.29 as written (``exact_5_29``), the LP under the
staging supervisor (wbc.planning.staging_supervisor) with its gains, the QP of the same rows and
terms (wbc.laws.qp_law), the cascade."""
STUDY_LAWS: dict[str, Callable[[MobileManipulator], Law]] = LAWS | {
    "lp with input change": lambda robot: LPLaw(robot, replace(LPParams(), **input_change_gains())),
}
"""The laws a study may run on goal families: ``LAWS``, and the LP with the input change term of
deploy/sim_smooth.yaml (``input_change_gains``)."""
POSITION_LAWS = ("lp", "lp 5.29 exactly", "qp", "cascade")
"""The laws run on the position task of each family's goals (6.2.2)."""


def not_reached(attempts: Iterable[Attempt]) -> dict[str, dict[str, int]]:
    """The goals not reached, by reason (most first)."""
    reasons: dict[str, int] = {}
    for a in attempts:
        if not a.converged:
            reasons[a.reason] = reasons.get(a.reason, 0) + 1
    return {"failures": dict(sorted(reasons.items(), key=lambda item: -item[1]))}


def failures(attempts: Iterable[Attempt]) -> dict:
    """The goals not reached, by reason (``not_reached``), and the contacts: runs whose base's
    body came within 0 of an obstacle, and the least clearance of all runs, m."""
    attempts = list(attempts)
    return {
        **not_reached(attempts),
        "contacts": sum(a.clearance < 0.0 for a in attempts),
        "least_clearance_m": min((a.clearance for a in attempts), default=math.inf),
    }
