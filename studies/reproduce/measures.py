"""The figures `parsimony reproduce` measures on a kinematic run: nonzero entries under one
counting rule, the residual of J u = -eta e, the bounds u meets, how abrupt u is, the paths
of the end effector and the base, the step time."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from studies.goal_sets import MOVING_ERROR, SETTLING_S
from wbc import dq
from wbc.geometry.obstacles import Circle
from wbc.laws.kinematic_run import Run
from wbc.laws.law_output import entry_mask
from wbc.laws.pinv_law import PINV_RCOND, nonholonomic_basis
from wbc.robot import BASE_DOF, MobileManipulator
from wbc.task import Task

ENTRIES = ("x'", "y'", "phi'", "q1'", "q2'", "q3'", "q4'", "q5'")
"""The entries of u = q', as figure 6.10 numbers q (q8 is the wrist's q5')."""
TOLERANCE = 1e-9
"""How near its bound an entry of u counts as on it."""
ERROR_BOUNDS = ("error_derivative_bound", "error_bound")
"""The names of the rows 5.10 and 5.7 (``wbc.laws.constraints.error_bound``)."""


def median(values: list[float]) -> float:
    return float(np.median(values)) if values else math.nan


def both_rules(masks: list[int]) -> list[float]:
    """The median count of ``masks`` (entry masks, ``wbc.laws.law_output.entry_mask``) as
    [entries of u, entries with x' and y' as one]."""
    return [
        median([m.bit_count() for m in masks]),
        median([m.bit_count() - (m & 3 == 3) for m in masks]),
    ]


def entry_counts(run: Run, practical: bool = False) -> dict[str, list[float]]:
    """Median nonzero entries of u while moving (||e|| > MOVING_ERROR) and over the last
    SETTLING_S, each as [entries of u, entries with x' and y' as one]: one rule in every
    column and phase. x' = v cos(phi) and y' = v sin(phi) carry one forward speed v; a base
    that has turned off an axis of the world frame needs both."""
    masks = [entry_mask(out.u, practical) for out in run.outputs]
    moving = [m for m, o in zip(masks, run.outputs, strict=True) if o.error_norm > MOVING_ERROR]
    last = masks[-round(SETTLING_S / run.dt) :]
    return {"moving": both_rules(moving), f"last {SETTLING_S:g} s": both_rules(last)}


def task_terms(robot: MobileManipulator, task: Task, q: np.ndarray) -> tuple[np.ndarray, ...]:
    """e and J of ``task`` at ``q``."""
    pose, jacobian = robot.kinematics(q)
    return task.error(pose, jacobian, q)


def residuals(
    run: Run, robot: MobileManipulator, task: Task | Sequence[Task], eta: float
) -> list[float]:
    """||J u + eta e|| / ||eta e|| at each step (of ``task``, or of the task of each step):
    0 where u realises J u = -eta e."""
    tasks = task if isinstance(task, Sequence) else [task] * len(run.outputs)
    out = []
    for q, step, current in zip(run.configurations, run.outputs, tasks, strict=True):
        error, jacobian = task_terms(robot, current, q)
        out.append(
            float(np.linalg.norm(jacobian @ step.u + eta * error) / np.linalg.norm(eta * error))
        )
    return out


def least_residual(
    robot: MobileManipulator, task: Task, q: np.ndarray, nonholonomic: bool
) -> float:
    """The least ||J u + eta e|| / ||eta e|| any u reaches at ``q`` (under 5.11 with
    ``nonholonomic``): the part of e outside the range of J (or of J N)."""
    error, jacobian = task_terms(robot, task, q)
    if nonholonomic:
        jacobian = jacobian @ nonholonomic_basis(float(q[2]), robot.dof)
    inside = jacobian @ (np.linalg.pinv(jacobian, rcond=PINV_RCOND) @ error)
    return float(np.linalg.norm(error - inside) / np.linalg.norm(error))


def wheel_speed(u: np.ndarray, phi: float, robot: MobileManipulator) -> float:
    """The faster wheel's speed for u at heading phi: |v| + |phi'| b / 2."""
    forward = u[0] * math.cos(phi) + u[1] * math.sin(phi)
    return abs(forward) + abs(u[2]) * robot.base.wheel_base / 2.0


def speeds(run: Run, robot: MobileManipulator) -> dict:
    """The bounds u meets: steps beyond a bound of ``robot.velocity_max`` or the wheel limit,
    steps on a speed bound by entry, steps on a bound of 5.15 (speed or joint limit) by entry
    where the law reports its active rows, the peaks and the heading's range."""
    u = run.velocities()
    phi = np.array(run.configurations)[:, 2]
    wheels = np.array([wheel_speed(v, p, robot) for v, p in zip(u, phi, strict=True)])
    bounds = robot.velocity_max
    beyond = np.any(np.abs(u) > bounds + TOLERANCE, axis=1)
    beyond |= wheels > robot.base.wheel_speed_max + TOLERANCE
    on = (np.abs(u) >= bounds - TOLERANCE).sum(axis=0)
    rows = [0] * robot.dof
    for out in run.outputs:
        for name in out.active_constraints:
            if name.startswith("joint_limits["):
                rows[int(name[13:-1])] += 1
    return {
        "steps beyond a bound": int(beyond.sum()),
        "on a speed bound": {ENTRIES[i]: int(n) for i, n in enumerate(on) if n},
        "on a bound of 5.15": {ENTRIES[i]: n for i, n in enumerate(rows) if n},
        "peak base m/s": float(np.hypot(u[:, 0], u[:, 1]).max()),
        "peak |phi'|": float(np.abs(u[:, 2]).max()),
        "peak wheel m/s": float(wheels.max()),
        "phi range": [float(phi.min()), float(phi.max())],
    }


BINDING = {
    "nonholonomic": "5.12",
    "error_derivative_bound": "5.10",
    "error_bound": "5.7",
    "obstacle_border": "5.28",
    "obstacle_vector_field": "the vector-field inequality",
}
"""The equation of each row group a law reports as active (``LawOutput.active_constraints``)."""


def binding(name: str) -> str:
    """An active row group by its equation; a bound of 5.15 with the entry it holds."""
    if name.startswith("joint_limits["):
        return f"5.15 on {ENTRIES[int(name[13:-1])]}"
    return BINDING.get(name, name)


def first_step(run: Run) -> dict:
    """u of the first step, its 2-norm and the rows that bind there (a law that reports them)."""
    out = run.outputs[0]
    return {
        "u": [round(float(v), 3) for v in out.u],
        "||u||_2": float(np.linalg.norm(out.u)),
        "binding": [binding(name) for name in out.active_constraints],
    }


def abruptness(run: Run) -> dict:
    """How abrupt u is: its total variation sum ||u_k+1 - u_k||_1 (table 6.1's metric 3 as
    the kinematic run takes it), the largest jump of one entry in one step (where and when),
    and the steps at which the set of nonzero entries changes (a switch of the LP's basis)."""
    u = run.velocities()
    jumps = np.abs(np.diff(u, axis=0))
    step, entry = np.unravel_index(int(np.argmax(jumps)), jumps.shape) if len(jumps) else (0, 0)
    masks = [entry_mask(out.u) for out in run.outputs]
    return {
        "total variation": float(jumps.sum()),
        "largest jump": float(jumps.max()) if len(jumps) else 0.0,
        "at": f"{ENTRIES[entry]}, t {(step + 1) * run.dt:.2f} s",
        "switches": sum(a != b for a, b in zip(masks, masks[1:], strict=False)),
    }


def end_effector_path(run: Run, robot: MobileManipulator, goal: np.ndarray) -> dict:
    """Figure 6.14: the end effector's path from its start to ``goal`` (a point): its length
    against the straight line's, its largest distance from that line, where it stops."""
    points = np.array([dq.translation(robot.fkm(q))[1:] for q in run.configurations])
    start = points[0]
    line = goal - start
    along = np.clip((points - start) @ line / (line @ line), 0.0, 1.0)
    off = np.linalg.norm(points - start - along[:, None] * line, axis=1)
    return {
        "length / straight line": float(
            np.linalg.norm(np.diff(points, axis=0), axis=1).sum() / np.linalg.norm(line)
        ),
        "largest distance from the line m": float(off.max()),
        "final distance m": float(np.linalg.norm(points[-1] - goal)),
    }


def round_obstacle(
    run: Run, robot: MobileManipulator, obstacle: Circle, goal_xy: np.ndarray
) -> dict:
    """Figure 6.16: the base going round ``obstacle`` on its way from its start towards
    ``goal_xy``: the least clearance of its body, its largest distance to either side of the
    straight line start-goal (left positive), whether it passed the obstacle along that line,
    the steps it stood still (no nonzero entry) with ||e|| > MOVING_ERROR, and the steps
    ||u||_1 sat on its bound (5.10's is 0 once the base stands still: e' = 0)."""
    base = np.array(run.configurations)[:, :2]
    start = base[0]
    line = goal_xy - start
    unit = line / np.linalg.norm(line)
    side = (base - start) @ np.array([-unit[1], unit[0]])
    gap = np.hypot(base[:, 0] - obstacle.x, base[:, 1] - obstacle.y) - obstacle.radius
    passed = bool(
        ((base - start) @ unit).max()
        > (np.array([obstacle.x, obstacle.y]) - start) @ unit + obstacle.radius
    )
    still = sum(out.nonzero == 0 and out.error_norm > MOVING_ERROR for out in run.outputs)
    bound = sum(any(name in ERROR_BOUNDS for name in out.active_constraints) for out in run.outputs)
    return {
        "least clearance m": float(gap.min() - robot.base.body_radius),
        "lateral excursion m": [float(side.min()), float(side.max())],
        "passed it": passed,
        "steps standing still": int(still),
        "steps on the bound of 5.10 / 5.7": int(bound),
    }


def obstacle_entries(run: Run) -> dict:
    """Figure 6.17 under one rule: median entries (x', y' as one in brackets) over the run and
    while an obstacle row is active, and the steps with all 8."""
    masks = [entry_mask(out.u) for out in run.outputs]
    engaged = [
        m
        for m, out in zip(masks, run.outputs, strict=True)
        if any(name.startswith("obstacle") for name in out.active_constraints)
    ]
    return {
        "run": both_rules(masks),
        "obstacle row active": both_rules(engaged),
        "steps with the row active": len(engaged),
        "steps with 8": sum(m.bit_count() == 8 for m in masks),
    }


def step_times_ms(runs: list[Run]) -> dict:
    """The law's own step (model, Jacobian, rows, solve; not the loop's messages): p50, p99
    and the largest, ms, over every step of ``runs``."""
    times = np.array([out.solve_time_s for run in runs for out in run.outputs]) * 1e3
    return {
        "steps": len(times),
        "p50": float(np.percentile(times, 50)),
        "p99": float(np.percentile(times, 99)),
        "max": float(times.max()),
    }


def worst_overrun(run: Run, robot: MobileManipulator) -> list:
    """Figure 6.10: the largest excursion of an arm joint beyond its limit (rad, 0 inside),
    and which entry of q (1-based, as q8 in figure 6.10)."""
    q = np.array(run.configurations)
    beyond = np.maximum(q - robot.q_max, robot.q_min - q).max(axis=0)
    entry = int(np.argmax(beyond[BASE_DOF:])) + BASE_DOF
    return [float(max(beyond[entry], 0.0)), f"q{entry + 1}" if beyond[entry] > 0 else "none"]
