"""Where the base should stand for a pose goal: whole-body configurations that reach it, ranked.

The LP law is local: from a base that faces away from a goal, or stands where the arm can only reach
it at a joint's limit, its steps stall. A staging candidate (``wbc.planning.candidate``) is a whole
configuration q_c with fkm(q_c) = x_d, found by a bounded inverse-kinematics search
(``wbc.planning.whole_body_ik``) from several starts, each arm joint kept a margin inside the LP's
joint box b_l [q-, q+] (5.14), so that the pose task started from q_c has room on every joint. The
starts place the base all round the goal, at reaches from behind the gripper to over the arm's back:
with the wrist rolled, the base of a configuration of the goal may face any way from the gripper's
heading, and the arm folded back puts the gripper behind the base. Candidates whose base, staging
point or final leg comes within reach of an obstacle are left out, and so are those with no way
round the obstacles to their staging point (wbc.planning.drive_planner), and those whose base,
staging point or way leaves the ``region`` the base must keep to (the floor the camera sees, where
the base keeps its fixes). Each candidate is scored, lower first:

    travel + heading_weight * turning + conditioning_weight * max(0, 1 - sigma_6 / sigma_floor)

with travel the length of the way to the staging point and of the final leg, turning the
heading changes of the drive that gets there (face the way's first leg, its arcs, then turn to
phi_c) and sigma_6 the conditioning of q_c (wbc.conditioning): near a singularity the last
metres of the pose task stall.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from wbc import dq
from wbc.conditioning import smallest_singular_value
from wbc.geometry.obstacles import Circle
from wbc.laws.lp_law import LPParams
from wbc.laws.objectives.base_target import gripper_heading
from wbc.planar import wrap
from wbc.planning.candidate import Candidate, clear_of, same_configuration, staging_point, within
from wbc.planning.disc_geometry import segment_clear
from wbc.planning.drive_planner import OutOfBudget, WayPlanner
from wbc.planning.way import Way
from wbc.planning.whole_body_ik import arm_box, solve_ik
from wbc.robot import BASE_DOF, MobileManipulator

Array = np.ndarray

NEAR_HEADING = 0.3
"""A base within a final leg of its candidate, facing it this closely and this close to its
heading (rad), with the straight way there clear, goes straight to the approach."""


@dataclass(frozen=True)
class StagingParams:
    """How candidates are searched for and ranked."""

    safety_factor: float = LPParams().safety_factor
    """b_l of the LP's joint limits."""
    joint_margins: tuple[float, ...] = (0.15, 0.05, 0.0)
    """Each arm joint of a candidate stays this far inside b_l [q-, q+], rad: the first margin
    that gives any candidate is kept (the last, 0, finds a goal whose only configurations
    lie at the box's edge: 'anywhere' draws its goals from the whole box)."""
    starts: int = 24
    turns: tuple[float, ...] = (
        0.0,
        math.pi,
        0.5 * math.pi,
        -0.5 * math.pi,
        0.25 * math.pi,
        -0.75 * math.pi,
        -0.25 * math.pi,
        0.75 * math.pi,
    )
    """The start's heading from the gripper's heading psi, rad (each with U(-0.2, 0.2) added),
    taken in turn: the base all round the goal."""
    reaches: tuple[float, ...] = (0.35, 0.15, -0.15)
    """The gripper's distance ahead of the start's base along its heading, m, taken in turn
    (negative: the arm folded over the base's back): over the goals 'anywhere' it spans -0.3
    to 0.45 m, median 0.16."""
    residual_tolerance: float = 1e-6
    heading_weight: float = 0.1
    """m of travel one radian of turning is worth."""
    sigma_floor: float = 0.03
    conditioning_weight: float = 1.0
    """m of travel a singular candidate is worth (scaled down to 0 at sigma_floor)."""
    clearance: float = LPParams().obstacle_margin
    """Extra distance between the base's body and an obstacle, m: the LP's margin."""
    slack: float = 0.1
    """Further room the way to a staging point keeps round obstacles where it can, and a
    roomy candidate keeps, m: near an obstacle the LP's obstacle row holds the base back."""
    final_legs: tuple[float, ...] = (0.4, -0.4, 0.2, -0.2, 0.0)
    """The straight drive into the candidate's pose, m, the first of these whose staging
    point and leg keep clear of obstacles: forward from this far behind the pose (negative:
    backwards from ahead of it; 0: the base turns into the pose where it stands)."""
    crowding_weight: float = 1.0
    """m of travel a candidate that is not roomy (``Candidate.roomy``) is worth: beside an
    obstacle the LP's obstacle row holds the base back from the pose (the vector-field
    inequality lets it near the margin no faster than eta_d d; 5.28 there demands the base move
    out faster than its speed bounds allow, and the program has no solution)."""
    region: tuple[tuple[float, float, float], ...] = ()
    """Where the base's axle must keep to, as half-planes (a, b, c), a x + b y <= c (a convex
    region: the floor the camera sees, ``sim2d.floor_view``); empty: anywhere."""
    max_distance: float = 10.0
    """A goal farther than this from the base is refused, m: the search's residual loses its
    precision far from the origin (a goal 100 m away took 2.1 s to fail)."""
    budget_s: float = 2.0
    """CPU seconds of the planning thread a whole plan may take (its own work, whatever else
    the machine does): building the way's graph (``WayPlanner``'s deadline) and the search
    both stop at it. Plans take 0.07 s median, 0.28 s p99 on the goals 'anywhere', 0.21 and
    0.77 s with an obstacle near the way (`parsimony bench`)."""
    seed: int = 0


@dataclass(frozen=True)
class Plan:
    """What a search found: the candidates, best score first, or why there is none."""

    candidates: tuple[Candidate, ...]
    reason: str
    """Why there is no candidate; empty when there are."""
    elapsed_s: float
    cpu_s: float = 0.0
    """The planning thread's CPU time, s (``elapsed_s`` also counts what else ran)."""


def plan(
    robot: MobileManipulator,
    q_now: Array,
    goal_pose: Array,
    obstacles: Sequence[Circle] = (),
    params: StagingParams = StagingParams(),
) -> Plan:
    """Every distinct configuration of the goal pose the search finds, each with its way,
    from the widest joint margin on until one is roomy (or the margins run out); with none,
    the reason: the goal refused at once (``refusal``), the CPU budget spent, every
    configuration found too near an obstacle or with no way to it, or none found. Pure but
    for the clocks: callable from any thread."""
    # SciPy's optimizer (0.3 s of CPU to import) is loaded here, before the clocks start, so
    # that a process that never plans does not load it and a first plan's budget is whole.
    import scipy.optimize  # noqa: F401

    started, cpu_started = time.perf_counter(), time.thread_time()

    def done(found: Sequence[Candidate], reason: str = "") -> Plan:
        return Plan(
            tuple(sorted(found, key=lambda c: c.score)),
            reason,
            time.perf_counter() - started,
            time.thread_time() - cpu_started,
        )

    refused = refusal(q_now, goal_pose, obstacles, params)
    if refused:
        return done((), refused)
    budget_end = time.thread_time() + params.budget_s
    spent = (
        f"no whole-body configuration found within the planning budget of "
        f"{params.budget_s:g} s of CPU time"
    )
    left_out = _LeftOut()
    found: list[Candidate] = []
    try:
        ways = WayPlanner(
            q_now[:2],
            obstacles,
            robot.base.body_radius + params.clearance,
            params.slack,
            deadline=budget_end,
        )
    except OutOfBudget as error:
        return done((), f"{spent} ({error})")
    for margin in params.joint_margins:
        more, finished = _search(
            robot, q_now, goal_pose, ways, params, margin, budget_end, left_out
        )
        found += [c for c in more if not any(same_configuration(c.q, o.q) for o in found)]
        if any(c.roomy for c in found):
            return done(found)
        if not finished:
            return done(found, "" if found else spent)
    if found:
        return done(found)
    if left_out.any:
        return done((), left_out.reason(params.clearance))
    return done((), "no whole-body configuration inside the joint box reaches the goal")


@dataclass
class _LeftOut:
    """The configurations of the goal a search left out, and why."""

    near: int = 0
    """Base, staging point or final leg within the clearance of an obstacle."""
    no_way: int = 0
    """No way round the obstacles to the staging point."""
    way_reason: str = ""
    outside: int = 0
    """Base, staging point or way outside the region."""

    @property
    def any(self) -> bool:
        return bool(self.near or self.no_way or self.outside)

    def reason(self, clearance: float) -> str:
        parts = []
        if self.near:
            parts.append(f"{self.near} bring the base within {clearance:g} m of an obstacle")
        if self.no_way:
            parts.append(f"{self.no_way} have no way to their staging point ({self.way_reason})")
        if self.outside:
            parts.append(f"{self.outside} take the base where the camera cannot see it")
        return (
            f"every whole-body configuration found that reaches the goal "
            f"({self.near + self.no_way + self.outside}) is left out: {'; '.join(parts)}"
        )


def refusal(
    q_now: Array, goal_pose: Array, obstacles: Sequence[Circle], params: StagingParams
) -> str:
    """Why a goal is refused before any search, or empty: its gripper inside an obstacle's
    circle, or farther than ``max_distance`` from the base."""
    x, y = dq.translation(goal_pose)[1:3]
    for index, c in enumerate(obstacles, start=1):
        if math.hypot(x - c.x, y - c.y) < c.radius:
            return (
                f"the goal ({x:.2f}, {y:.2f}) lies inside obstacle {index} at "
                f"({c.x:.2f}, {c.y:.2f}), radius {c.radius:g} m"
            )
    distance = math.hypot(x - q_now[0], y - q_now[1])
    if distance > params.max_distance:
        return (
            f"the goal is {distance:.1f} m from the base, farther than the "
            f"{params.max_distance:g} m a plan may cover"
        )
    return ""


def _start(
    rng: np.random.Generator,
    index: int,
    goal_xy: Array,
    psi: float,
    params: StagingParams,
    arm: tuple[Array, Array],
) -> Array:
    """The ``index``-th start: the base ``reach`` behind the goal along a heading ``turn``
    from the gripper's, the arm uniform in its box."""
    yaw = psi + params.turns[index % len(params.turns)] + rng.uniform(-0.2, 0.2)
    reach = params.reaches[index % len(params.reaches)]
    base = goal_xy - reach * np.array([math.cos(yaw), math.sin(yaw)])
    return np.concatenate((base, [yaw], rng.uniform(*arm)))


def _search(
    robot: MobileManipulator,
    q_now: Array,
    goal_pose: Array,
    ways: WayPlanner,
    params: StagingParams,
    margin: float,
    budget_end: float,
    left_out: _LeftOut,
) -> tuple[list[Candidate], bool]:
    """The candidates of one margin in the order found (``plan`` ranks them; those left out
    are counted in ``left_out``), each with its way from ``ways``, and whether every start was
    tried before the CPU budget ran out."""
    obstacles = ways.obstacles
    rng = np.random.default_rng(params.seed)
    low, high = arm_box(robot, params.safety_factor, margin)
    inf = np.full(BASE_DOF, np.inf)
    bounds = (np.concatenate((-inf, low[1:])), np.concatenate((inf, high[1:])))
    psi = gripper_heading(goal_pose)
    goal_xy = dq.translation(goal_pose)[1:3]
    body = robot.base.body_radius + params.clearance
    found: list[Candidate] = []
    seen: list[Array] = []
    for index in range(params.starts):
        if time.thread_time() > budget_end:
            return found, False
        start = _start(rng, index, goal_xy, psi, params, (low, high))
        q = solve_ik(robot, goal_pose, start, bounds, params.residual_tolerance)
        if q is None or any(same_configuration(q, other) for other in seen):
            continue
        seen.append(q)
        final_leg = _final_leg(q, obstacles, body, params.final_legs)
        if final_leg is None:
            left_out.near += 1
            continue
        if not within(params.region, q, staging_point(q[:BASE_DOF], final_leg)):
            left_out.outside += 1
            continue
        if _near(q_now, q, params.final_legs[0]) and segment_clear(q_now, q, obstacles, body):
            found.append(_scored(robot, q_now, q, None, final_leg, obstacles, params))
            continue
        try:
            way = ways.to(staging_point(q[:BASE_DOF], final_leg))
        except OutOfBudget:
            return found, False
        if not way.found:
            left_out.no_way += 1
            left_out.way_reason = way.reason
            continue
        if not within(params.region, *way.waypoints):
            left_out.outside += 1
            continue
        found.append(_scored(robot, q_now, q, way, final_leg, obstacles, params))
    return found, True


def _final_leg(
    q: Array, obstacles: Sequence[Circle], body: float, legs: Sequence[float]
) -> float | None:
    """The first of ``legs`` whose staging point and straight leg into q's base keep ``body``
    from every obstacle, None when the base itself does not or none does."""
    if not clear_of(obstacles, q, body):
        return None
    for leg in legs:
        staging = staging_point(q[:BASE_DOF], leg)
        if clear_of(obstacles, staging, body) and segment_clear(staging, q, obstacles, body):
            return leg
    return None


def _near(q_now: Array, q: Array, final_leg: float) -> bool:
    """q's base within ``final_leg`` of the base now, ahead of it, both headings within
    ``NEAR_HEADING``: the straight approach gets there without swinging the base round."""
    offset = q[:2] - q_now[:2]
    distance = math.hypot(*offset)
    ahead = distance < 0.01 or abs(wrap(math.atan2(offset[1], offset[0]) - q_now[2])) < NEAR_HEADING
    return bool(distance < final_leg and ahead and abs(wrap(q[2] - q_now[2])) < NEAR_HEADING)


def _scored(
    robot: MobileManipulator,
    q_now: Array,
    q: Array,
    way: Way | None,
    final_leg: float,
    obstacles: Sequence[Circle],
    params: StagingParams,
) -> Candidate:
    """The candidate q reached by ``way`` and the final leg, or straight (``way`` None)."""
    if way is None:
        travel = float(math.hypot(*(q[:2] - q_now[:2])))
        turning = abs(wrap(q[2] - q_now[2]))
    else:
        travel = way.length + abs(final_leg)
        turning = (
            abs(wrap(way.first_bearing() - q_now[2]))
            + way.turning
            + abs(wrap(q[2] - way.last_bearing()))
        )
    sigma = smallest_singular_value(robot, q)
    penalty = params.conditioning_weight * max(0.0, 1.0 - sigma / params.sigma_floor)
    room = robot.base.body_radius + params.clearance + params.slack
    ahead = q[:2] + params.slack * np.array([math.cos(q[2]), math.sin(q[2])])
    roomy = clear_of(obstacles, ahead, room) and clear_of(
        obstacles, staging_point(q[:BASE_DOF], final_leg), room
    )
    score = travel + params.heading_weight * turning + penalty
    score += 0.0 if roomy else params.crowding_weight
    return Candidate(q, travel, turning, sigma, score, way, final_leg, roomy)
