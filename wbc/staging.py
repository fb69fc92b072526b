"""Where the base should stand for a pose goal: whole-body configurations that reach it, ranked.

The LP law is local: from a base that faces away from a goal, or stands where the arm can only
reach it at a joint's limit, its steps stall. A staging candidate is a whole configuration q_c
with fkm(q_c) = x_d, found by a bounded inverse-kinematics search from several starts:

    min ||vec8(fkm(q)) - vec8(x_d)||^2  over  z = (x, y, phi, q2, q3, q4, q5),  q1 = 0,

each arm joint kept a margin inside the LP's joint box b_l [q-, q+] (5.14), so that the
pose task started from q_c has room on every joint. The waist is held at 0: it turns the arm
exactly as phi does (the arm stands on the base's turning axis), so the base's heading carries
the arm's yaw. Candidates whose base or staging point comes within reach of an obstacle are
left out. Each candidate is scored, lower first:

    travel + heading_weight * turning + conditioning_weight * max(0, 1 - sigma_6 / sigma_floor)

with travel the base's distance to q_c, turning the heading changes of the drive that gets
there (face the staging point, then turn to phi_c) and sigma_6 the conditioning of q_c
(wbc.conditioning): near a singularity the last metres of the pose task stall.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from wbc import dq
from wbc.conditioning import smallest_singular_value
from wbc.lp_law import LPParams
from wbc.objectives.base_target import gripper_heading
from wbc.obstacles import Circle
from wbc.planar import wrap
from wbc.robot import BASE_DOF, MobileManipulator

Array = np.ndarray

FREE = [0, 1, 2, 4, 5, 6, 7]
"""The entries of q the search moves: the base and every arm joint but the waist."""


@dataclass(frozen=True)
class StagingParams:
    """How candidates are searched for and ranked."""

    safety_factor: float = LPParams().safety_factor
    """b_l of the LP's joint limits."""
    joint_margins: tuple[float, ...] = (0.15, 0.05)
    """Each arm joint of a candidate stays this far inside b_l [q-, q+], rad: the first margin
    that gives any candidate is kept."""
    starts: int = 16
    reaches: tuple[float, ...] = (0.2, 0.35, 0.5)
    """Distances behind the goal, along the gripper's heading, the search starts the base at."""
    residual_tolerance: float = 1e-6
    heading_weight: float = 0.1
    """m of travel one radian of turning is worth."""
    sigma_floor: float = 0.03
    conditioning_weight: float = 1.0
    """m of travel a singular candidate is worth (scaled down to 0 at sigma_floor)."""
    clearance: float = LPParams().obstacle_margin
    """Extra distance between the base's body and an obstacle, m: the LP's margin."""
    final_leg: float = 0.4
    """The straight drive into the candidate's pose starts this far behind it, m."""
    max_distance: float = 10.0
    """A goal farther than this from the base is refused, m: a staging plan drives straight,
    and the search's residual loses its precision far from the origin (a goal 100 m away
    took 2.1 s to fail)."""
    budget_s: float = 2.0
    """CPU seconds of the planning thread a search may take (its own work, whatever else
    the machine does): no new start is tried past it. Plans take 0.05 s median, 0.2 s p99."""
    seed: int = 0


@dataclass(frozen=True)
class Candidate:
    """A configuration of the goal pose and what getting there costs."""

    q: Array
    travel: float
    turning: float
    sigma: float
    score: float

    @property
    def base(self) -> Array:
        return self.q[:BASE_DOF]

    @property
    def arm(self) -> Array:
        return self.q[BASE_DOF:]

    def staging_point(self, final_leg: float) -> Array:
        return staging_point(self.base, final_leg)


def staging_point(base: Array, final_leg: float) -> Array:
    """Where the final straight leg into a base pose (x, y, phi) starts: ``final_leg`` behind
    it, on its heading."""
    x, y, phi = base
    return np.array([x - final_leg * math.cos(phi), y - final_leg * math.sin(phi)])


def arm_box(robot: MobileManipulator, safety_factor: float, margin: float
            ) -> tuple[Array, Array]:  # fmt: skip
    """The arm joints' search bounds: b_l [q-, q+] shrunk by ``margin`` on each side."""
    low = safety_factor * robot.q_min[BASE_DOF:] + margin
    high = safety_factor * robot.q_max[BASE_DOF:] - margin
    return low, high


def solve_ik(robot: MobileManipulator, goal_pose: Array, start: Array,
             bounds: tuple[Array, Array], tolerance: float) -> Array | None:  # fmt: skip
    """A configuration q (q1 = 0) with fkm(q) = goal_pose from ``start``, or None."""
    q = np.array(start, dtype=float)
    q[BASE_DOF] = 0.0
    goal = dq.nearest_equivalent(goal_pose, robot.fkm(q))

    def residual(z: Array) -> Array:
        q[FREE] = z
        return robot.fkm(q) - goal

    def jacobian(z: Array) -> Array:
        q[FREE] = z
        return robot.pose_jacobian(q)[:, FREE]

    result = least_squares(residual, q[FREE], jac=jacobian, bounds=bounds, method="trf",
                           xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=200)  # fmt: skip
    if not math.sqrt(2.0 * result.cost) < tolerance:
        return None
    q[FREE] = result.x
    q[2] = wrap(q[2])
    return q.copy()


def clear_of(obstacles: Sequence[Circle], point: Array, body_radius: float) -> bool:
    return all(math.hypot(point[0] - c.x, point[1] - c.y) >= c.radius + body_radius
               for c in obstacles)  # fmt: skip


@dataclass(frozen=True)
class Plan:
    """What a search found: the candidates, best score first, or why there is none."""

    candidates: tuple[Candidate, ...]
    reason: str
    """Why there is no candidate; empty when there are."""
    elapsed_s: float


def plan(robot: MobileManipulator, q_now: Array, goal_pose: Array,
         obstacles: Sequence[Circle] = (), params: StagingParams = StagingParams()
         ) -> Plan:  # fmt: skip
    """Every distinct configuration of the goal pose the search finds, with the widest joint
    margin that gives any; with none, the reason: the goal refused at once (``refusal``), the
    CPU budget spent, every configuration found too near an obstacle, or none found. Pure
    but for the clocks: callable from any thread."""
    started = time.perf_counter()

    def done(found: Sequence[Candidate], reason: str = "") -> Plan:
        return Plan(tuple(found), reason, time.perf_counter() - started)

    refused = refusal(q_now, goal_pose, obstacles, params)
    if refused:
        return done((), refused)
    budget_end = time.thread_time() + params.budget_s
    blocked = 0
    for margin in params.joint_margins:
        found, near_obstacles, finished = _search(robot, q_now, goal_pose, obstacles, params,
                                                  margin, budget_end)  # fmt: skip
        if found:
            return done(found)
        blocked += near_obstacles
        if not finished:
            return done((), "no whole-body configuration found within the planning budget "
                        f"of {params.budget_s:g} s of CPU time")  # fmt: skip
    if blocked:
        return done((), f"every whole-body configuration found that reaches the goal ({blocked}) "
                    f"brings the base within {params.clearance:g} m of an obstacle")  # fmt: skip
    return done((), "no whole-body configuration inside the joint box reaches the goal")


def refusal(q_now: Array, goal_pose: Array, obstacles: Sequence[Circle],
            params: StagingParams) -> str:  # fmt: skip
    """Why a goal is refused before any search, or empty: its gripper inside an obstacle's
    circle, or farther than ``max_distance`` from the base."""
    x, y = dq.translation(goal_pose)[1:3]
    for index, c in enumerate(obstacles, start=1):
        if math.hypot(x - c.x, y - c.y) < c.radius:
            return (f"the goal ({x:.2f}, {y:.2f}) lies inside obstacle {index} at "
                    f"({c.x:.2f}, {c.y:.2f}), radius {c.radius:g} m")  # fmt: skip
    distance = math.hypot(x - q_now[0], y - q_now[1])
    if distance > params.max_distance:
        return (f"the goal is {distance:.1f} m from the base, farther than the "
                f"{params.max_distance:g} m a plan may cover")  # fmt: skip
    return ""


def _search(robot: MobileManipulator, q_now: Array, goal_pose: Array,
            obstacles: Sequence[Circle], params: StagingParams, margin: float,
            budget_end: float) -> tuple[list[Candidate], int, bool]:  # fmt: skip
    """The candidates of one margin, how many were left out near obstacles, and whether every
    start was tried before the CPU budget ran out."""
    rng = np.random.default_rng(params.seed)
    low, high = arm_box(robot, params.safety_factor, margin)
    inf = np.full(BASE_DOF, np.inf)
    bounds = (np.concatenate((-inf, low[1:])), np.concatenate((inf, high[1:])))
    psi = gripper_heading(goal_pose)
    goal_xy = dq.translation(goal_pose)[1:3]
    body = robot.base.body_radius + params.clearance
    found: list[Candidate] = []
    blocked = 0
    for index in range(params.starts):
        if time.thread_time() > budget_end:
            return sorted(found, key=lambda c: c.score), blocked, False
        yaw = psi + (math.pi if index % 4 == 3 else rng.uniform(-0.5, 0.5))
        reach = params.reaches[index % len(params.reaches)]
        start = np.concatenate((goal_xy - reach * np.array([math.cos(yaw), math.sin(yaw)]),
                                [yaw], rng.uniform(low, high)))  # fmt: skip
        q = solve_ik(robot, goal_pose, start, bounds, params.residual_tolerance)
        if q is None or any(same_configuration(q, c.q) for c in found):
            continue
        candidate = _scored(robot, q_now, q, params)
        if clear_of(obstacles, candidate.base, body) and clear_of(
            obstacles, candidate.staging_point(params.final_leg), body
        ):
            found.append(candidate)
        else:
            blocked += 1
    return sorted(found, key=lambda c: c.score), blocked, True


def same_configuration(a: Array, b: Array) -> bool:
    """Every entry within 0.02 (m or rad, headings wrapped)."""
    return bool(np.max(np.abs(np.concatenate((a[:2] - b[:2], [wrap(a[2] - b[2])],
                                              a[BASE_DOF:] - b[BASE_DOF:])))) < 0.02)  # fmt: skip


def _scored(robot: MobileManipulator, q_now: Array, q: Array, params: StagingParams) -> Candidate:
    travel = float(math.hypot(q[0] - q_now[0], q[1] - q_now[1]))
    staging = staging_point(q[:BASE_DOF], params.final_leg)
    bearing = math.atan2(staging[1] - q_now[1], staging[0] - q_now[0])
    # The base may drive its first leg backwards: turning is counted modulo a half turn.
    face = abs(wrap(2.0 * (bearing - q_now[2]))) / 2.0
    turning = face + abs(wrap(q[2] - bearing))
    sigma = smallest_singular_value(robot, q)
    penalty = params.conditioning_weight * max(0.0, 1.0 - sigma / params.sigma_floor)
    score = travel + params.heading_weight * turning + penalty
    return Candidate(q, travel, turning, sigma, score)

