"""What one control step costs, law by law: on Little John's trajectory and on every robot of the
zoo (deploy/robots), the laws taking turns over the same states.

Step times are taken on a replay of a closed-loop LP trajectory, so the LP's warm start sees the
small changes it sees in a control loop. Every figure comes from one run on this machine.
"""

from __future__ import annotations

import copy
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path

import numpy as np

from profiles.deploy_files import ROBOT_FILE
from wbc.geometry.scenarios import DT, HOME, REACH_GOAL
from wbc.laws import lp_law
from wbc.laws.cascade_law import CascadeLaw
from wbc.laws.kinematic_run import integrate
from wbc.laws.law_output import Law
from wbc.laws.lp_law import LPLaw
from wbc.laws.pinv_law import PseudoinverseLaw
from wbc.laws.qp_law import QPLaw
from wbc.robot import BASE_DOF, MobileManipulator
from wbc.task import PoseTask

Array = np.ndarray
TRAJECTORY_STEPS = 3000
"""The longest LP trajectory replayed (it stops earlier where the goal is reached)."""


def percentiles(samples_s: list[float]) -> dict[str, float]:
    """Median and p99 of durations in seconds, in microseconds."""
    values = np.asarray(samples_s) * 1e6
    return {"median_us": float(np.median(values)), "p99_us": float(np.percentile(values, 99))}


def time_calls(call: Callable[[], object], repeats: int) -> list[float]:
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        samples.append(time.perf_counter() - start)
    return samples


BLOCK = 100
"""Steps each law takes in turn: long enough to run with warm caches, short enough that a
drift of the machine's speed reaches every law alike."""


def blocks(
    trajectory: Sequence[Array], repeats: int, laws: Iterable[Law]
) -> Iterator[Sequence[Array]]:
    """``repeats`` states of ``trajectory`` in slices of BLOCK, wrapping round to its start,
    where every law is reset."""
    position = done = 0
    while done < repeats:
        if position == 0:
            for law in laws:
                law.reset()
        block = trajectory[position : position + min(BLOCK, repeats - done)]
        yield block
        done += len(block)
        position = (position + len(block)) % len(trajectory)


def laws_for(robot: MobileManipulator) -> dict[str, Law]:
    """The laws timed on ``robot``: the LP, the QP, the classic law (the pseudoinverse) and,
    where the base is differential, the cascade of appendix B."""
    laws: dict[str, Law] = {
        "lp": LPLaw(robot),
        "qp": QPLaw(robot),
        "classic": PseudoinverseLaw(robot),
    }
    if robot.base.kind == "differential":
        laws["cascade"] = CascadeLaw(robot)
    return laws


def scenario(robot: MobileManipulator) -> tuple[Array, Array]:
    """A start and a goal configuration for any robot: the arm a tenth of its range off the
    middle of its limits, joint by joint in alternate directions (no straight, singular chain),
    and the goal the arm moved by up to a fifth of its range (a fixed seed) and, unless the base
    is fixed, the base 0.4 m ahead, 0.1 m left, turned 0.2 rad."""
    low, high = robot.q_min[BASE_DOF:], robot.q_max[BASE_DOF:]
    middle, span = 0.5 * (low + high), high - low
    signs = np.where(np.arange(robot.arm_dof) % 2 == 0, 1.0, -1.0)
    arm = middle + 0.1 * span * signs
    moved = arm + 0.2 * span * np.random.default_rng(0).uniform(-1.0, 1.0, robot.arm_dof)
    moved = np.clip(moved, low + 0.1 * span, high - 0.1 * span)
    base = np.zeros(BASE_DOF) if robot.base.kind == "fixed" else np.array([0.4, 0.1, 0.2])
    return np.concatenate((np.zeros(BASE_DOF), arm)), np.concatenate((base, moved))


def trajectory(
    robot: MobileManipulator, start: Array, goal: Array, steps: int = TRAJECTORY_STEPS
) -> list[Array]:
    """The states of a closed-loop LP run from ``start`` towards the pose of ``goal``, at most
    ``steps`` (a bench of fewer steps than TRAJECTORY_STEPS replays no more than it times)."""
    task = PoseTask(robot.fkm(goal))
    return integrate(LPLaw(robot), start, task, DT, min(steps, TRAJECTORY_STEPS)).configurations


def step_times(
    robot: MobileManipulator, repeats: int, start: Array = HOME, goal: Array = REACH_GOAL
) -> dict[str, dict[str, float]]:
    """Whole control steps (model, Jacobian, rows, solve) along a recorded LP trajectory from
    ``start`` towards the pose of ``goal``, and the kinematics alone at ``goal``.

    The laws take turns, BLOCK steps each, over the same states.
    """
    task = PoseTask(robot.fkm(goal))
    states = trajectory(robot, start, goal, repeats)
    laws = laws_for(robot)
    samples: dict[str, list[float]] = {name: [] for name in laws}
    for block in blocks(states, repeats, laws.values()):
        for name, law in laws.items():
            for q in block:
                begin = time.perf_counter()
                law.step(q, task, DT)
                samples[name].append(time.perf_counter() - begin)
    results = {name: percentiles(values) for name, values in samples.items()}
    results["kinematics"] = percentiles(time_calls(lambda: robot.kinematics(goal), repeats))
    return results


def lp_breakdown(
    robot: MobileManipulator, repeats: int, start: Array = HOME, goal: Array = REACH_GOAL
) -> dict[str, float]:
    """Median microseconds of one LP step spent in each part, the rest being Python glue.

    The law's own parts are wrapped with timers: the forward pass (fkm and J), the rows and
    terms (the task's error e and Jacobian at x, ``task.error``, its rate e', ``lp_law.
    error_rate``, then ``lp_law.terms``: the constraints' rows and the objective's terms, the
    task's ||J u + eta e|| first), the vertex (the LP solved from its data: the costs of u_P and
    u_N, the kept basis tested or the calls into HiGHS, u = u_P - u_N) and HiGHS alone (model
    update, basis, run, solution); ``highs_runs`` is the share of steps that called HiGHS. The
    step (``total``) is the law's own, untimed: a twin law with no timers steps the same states
    in turn, BLOCK at a time, and a step's glue is its time less the parts the timed law spent
    on the same state (the two in alternate order, block by block), so of the timers' own cost
    (about half a microsecond a call) only what a timer does between its two reads of the clock
    falls in a part. Both laws give the same outputs, so take the same path, at each state.
    """
    task, plain = PoseTask(robot.fkm(goal)), PoseTask(robot.fkm(goal))
    states = trajectory(robot, start, goal, repeats)
    law, twin = LPLaw(robot), LPLaw(robot)
    law.step(start, task, DT)
    twin.step(start, plain, DT)
    spent = {"kinematics": 0.0, "rows": 0.0, "vertex": 0.0, "highs": 0.0}

    def timed(part: str, call: Callable) -> Callable:
        def wrapper(*args: object) -> object:
            begin = time.perf_counter()
            result = call(*args)
            spent[part] += time.perf_counter() - begin
            return result

        return wrapper

    law.robot = copy.copy(robot)
    law.robot.forward = timed("kinematics", robot.forward)  # type: ignore[method-assign]
    # The task's term (e, J of ||J u + eta e||) is timed as the other terms are.
    object.__setattr__(task, "error", timed("rows", task.error))
    law._lp._optimum = timed("vertex", law._lp._optimum)  # type: ignore[method-assign]
    law._lp._run = timed("highs", law._lp._run)  # type: ignore[method-assign]
    parts: dict[str, list[float]] = {name: [] for name in (*spent, "glue", "total")}
    # The module's functions the step calls, timed for the law and as they are for its twin.
    plain_calls = {name: getattr(lp_law, name) for name in ("error_rate", "terms")}
    timed_calls = {name: timed("rows", call) for name, call in plain_calls.items()}
    untimed: list[float] = []
    try:
        for index, block in enumerate(blocks(states, repeats, (law, twin))):
            for twin_turn in (index % 2 == 1, index % 2 == 0):  # each first every other block
                for name, call in (plain_calls if twin_turn else timed_calls).items():
                    setattr(lp_law, name, call)
                for q in block:
                    spent.update(dict.fromkeys(spent, 0.0))
                    begin = time.perf_counter()
                    (twin if twin_turn else law).step(q, plain if twin_turn else task, DT)
                    elapsed = time.perf_counter() - begin
                    if twin_turn:
                        untimed.append(elapsed)
                    else:
                        for name, value in spent.items():
                            parts[name].append(value)
    finally:
        for name, call in plain_calls.items():
            setattr(lp_law, name, call)
    named = np.sum([parts[name] for name in ("kinematics", "rows", "vertex")], axis=0)
    parts["glue"], parts["total"] = list(np.array(untimed) - named), untimed
    result = {name: float(np.median(values) * 1e6) for name, values in parts.items()}
    result["highs_runs"] = float(np.mean(np.array(parts["highs"]) > 0.0))
    return result


def medians(runs: Sequence[dict[str, float]]) -> dict[str, float]:
    """Each figure of the ``runs`` (dicts with the same keys), the median of its values."""
    return {key: float(np.median([run[key] for run in runs])) for key in runs[0]}


def zoo_step_times(robot_files: Iterable[Path], repeats: int, runs: int = 1) -> dict[str, dict]:
    """Per robot of the zoo (by its name): its size, each law's step time on its own
    ``scenario`` (Little John's: its experiments' HOME and REACH_GOAL, as ``step_times``), the
    LP's median over the classic law's (same run) and the LP step's parts.

    ``runs`` times over, every robot in turn in each run (a machine whose speed drifts drifts
    for all): each figure is the median of the runs' (``lp_over_classic`` of each run's ratio),
    and ``glue_share``, the glue's share of the LP step, gives each run's with their median and
    range (``runs``, ``median``, ``low``, ``high``)."""
    files = list(robot_files)
    robots = [MobileManipulator.from_yaml(path) for path in files]
    scenarios = [
        (HOME, REACH_GOAL) if Path(path).resolve() == ROBOT_FILE.resolve() else scenario(robot)
        for path, robot in zip(files, robots, strict=True)
    ]
    measured: dict[str, list[tuple[dict, dict]]] = {robot.name: [] for robot in robots}
    for _ in range(runs):
        for robot, (start, goal) in zip(robots, scenarios, strict=True):
            steps = step_times(robot, repeats, start, goal)
            measured[robot.name].append((steps, lp_breakdown(robot, repeats, start, goal)))
    results = {}
    for robot in robots:
        taken = measured[robot.name]
        shares = [parts["glue"] / parts["total"] for _, parts in taken]
        results[robot.name] = {
            "dof": robot.dof,
            "arm_dof": robot.arm_dof,
            "base": robot.base.kind,
            "step": {law: medians([steps[law] for steps, _ in taken]) for law in taken[0][0]},
            "lp_over_classic": float(
                np.median([s["lp"]["median_us"] / s["classic"]["median_us"] for s, _ in taken])
            ),
            "lp_breakdown_us": medians([parts for _, parts in taken]),
            "glue_share": {
                "runs": shares,
                "median": float(np.median(shares)),
                "low": min(shares),
                "high": max(shares),
            },
        }
    return results
