"""The supervisor process between the operator's goal and the controller's (real Zenoh)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numpy as np
import pytest
import yaml

from components.control_step import task_of
from components.controller import goal_of
from components.robot_sight import sight_region
from launch.query import status_of
from messages import codec
from messages.goal import Goal
from messages.header import Header
from messages.obstacles import Circle, Obstacles
from messages.supervisor import SupervisorStatus
from profiles.deploy_files import DEPLOY
from profiles.profile_files import read_profile_data
from tests.components.conftest import DEADLINE_S, System
from tests.components.driver_harness import status as component_status
from tests.components.supervised import MODEL, PROFILE, Operator, header, met_at, supervised
from tests.wbc.planning.crowd import CHECK_GAP_S, crowd
from wbc import dq
from wbc.geometry.scenarios import HOME, REACH_GOAL
from wbc.planar import planar_pose
from wbc.planning.candidate import within
from wbc.planning.drive_tasks import HeadingTask, PointTask
from wbc.task import PoseTask, PositionTask, same_task


def test_a_goal_behind_the_robot_is_planned_off_the_handler_thread_then_driven_to(
    deployed: Callable[[str], System],
) -> None:
    """While the plan runs the controller is told to hold where the robot stands, and the
    status says so: both come from the state that asked for the plan, before it returned."""
    operator = supervised(deployed)
    assert operator.statuses.messages[0].phase == "idle"
    behind = operator.robot.fkm(np.concatenate(([-0.8, 0.2, 3.0], REACH_GOAL[3:])))
    asked = operator.ask(behind)
    operator.answer_to(asked, HOME, "the goal taken")
    first = operator.goals.wait_for(lambda g: True, "the controller's first goal")
    planning = operator.statuses.wait_for(lambda s: s.phase != "idle", "a status of the goal")
    assert planning.phase == "planning" and planning.plans == 0
    assert first.task == "point" and first.arm is not None and first.lookahead is not None
    np.testing.assert_allclose(first.arm, HOME[3:])
    np.testing.assert_allclose(first.point, HOME[:2] + [first.lookahead, 0.0])

    status = operator.statuses.wait_for(
        lambda s: s.phase not in ("idle", "planning"),
        "the plan's first phase, as soon as it is made",
    )
    operator.send_state(HOME)
    assert status.phase == "drive" and status.plans == 1 and status.candidate == 1
    assert status.candidate_base is not None and status.candidate_base[0] < -0.3
    assert status.planning_ms is not None and status.planning_ms > 0.0
    drive = operator.goals.wait_for(
        lambda g: (
            g.task == "heading" or (g.point is not None and not np.allclose(g.point, first.point))
        ),
        "the drive leg",
    )
    assert drive.task == "heading"  # the base faces away from the way: it turns to face it


def take_obstacles(operator: Operator, circles: tuple[Circle, ...]) -> None:
    """Publish ``circles`` until the supervisor has received them."""
    deadline = time.monotonic() + DEADLINE_S
    while component_status(operator.system, "supervisor").counters["received.world/obstacles"] == 0:
        assert time.monotonic() < deadline, "the supervisor never took the obstacles"
        operator.obstacles.put(codec.encode(Obstacles(header=header(), circles=circles)))


def test_the_status_of_a_drive_round_an_obstacle_carries_its_whole_planned_way(
    deployed: Callable[[str], System],
) -> None:
    """A post on the way to a goal behind the robot: the status of the drive names every
    waypoint still to pass, round the post with the base's body clear of it, and the
    candidate's base last."""
    operator = supervised(deployed)
    post = Circle(x=-0.4, y=0.1, radius=0.15)
    take_obstacles(operator, (post,))
    behind = operator.robot.fkm(np.concatenate(([-0.8, 0.2, 3.0], REACH_GOAL[3:])))
    asked = operator.ask(behind)
    operator.answer_to(asked, HOME, "the goal taken")
    drive = operator.statuses.wait_for(lambda s: s.phase == "drive", "the drive's status")
    assert len(drive.way) > 2, drive.way  # a way round the post, not straight at it
    assert drive.candidate_base is not None
    np.testing.assert_allclose(drive.way[-1], drive.candidate_base[:2])
    points = np.array([HOME[:2], *drive.way])
    centre = np.array([post.x, post.y])
    for a, b in zip(points, points[1:], strict=False):
        along = np.clip(np.dot(centre - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0)
        gap = np.linalg.norm(a + along * (b - a) - centre)
        assert gap > post.radius + MODEL.base.body_radius, (a, b, gap)


def unreachable(operator: Operator, pose: np.ndarray, why: str = "") -> SupervisorStatus:
    """Ask for ``pose``; the first status that says it is unreachable (for a reason that holds
    ``why``: a goal asked before may still be said unreachable for its own)."""
    operator.ask(pose)

    def found() -> SupervisorStatus | None:
        statuses = operator.statuses.messages
        return next((s for s in statuses if s.phase == "unreachable" and why in s.reason), None)

    deadline = time.monotonic() + DEADLINE_S
    while (status := found()) is None:
        assert time.monotonic() < deadline, f"the goal was never reported unreachable ({why})"
        operator.send_state(HOME)
        time.sleep(0.02)
    return status


def test_unreachable_goals_are_reported_with_their_reason_and_the_robot_is_held(
    deployed: Callable[[str], System],
) -> None:
    """One supervisor, three goals in turn (each had a supervisor of its own): 2 m above the
    floor, no whole-body configuration; 100 m away, refused at once (it took 2.1 s to fail, and
    over 3 s in the running system: the launcher's watchdog killed the supervisor and the goal
    was forgotten); inside an obstacle, said so. Meanwhile the robot is held where it stands."""
    operator = supervised(deployed)
    status = unreachable(operator, planar_pose(0.5, 0.0, 0.0, 2.0), "no whole-body")
    hold = operator.goals.wait_for(lambda g: g.task == "point", "the hold")
    np.testing.assert_allclose(hold.arm, HOME[3:])
    np.testing.assert_allclose(hold.point, HOME[:2] + [hold.lookahead, 0.0])

    status = unreachable(operator, planar_pose(100.0, 0.0, 0.0, 0.3), "farther than the 10 m")
    assert "farther than the 10 m a plan may cover" in status.reason
    assert status.planning_ms is not None and status.planning_ms < 100.0
    assert operator.goals.messages[-1].task == "point"
    answer = component_status(operator.system, "supervisor")
    assert answer is not None and answer.counters["unreachable"] == 2

    goal = operator.robot.fkm(REACH_GOAL)
    x, y = dq.translation(goal)[1:3]
    take_obstacles(operator, (Circle(x=x + 0.02, y=y, radius=0.1),))
    unreachable(operator, goal, "lies inside obstacle 1")


REFUSED_REQUESTS = [
    ({"pose": (math.nan, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)}, "pose"),
    ({"pose": (2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)}, "pose"),
    ({"pose": (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)}, "pose"),
    ({"pose": (1.0, 0.0, 0.0, 0.0, 0.3, 0.0, 0.0, 0.0)}, "pose"),
    ({"pose": (0.0,) * 8}, "pose"),
    ({"pose": (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0), "eta": -1.0}, "eta"),
]
"""Requests the supervisor refuses (a NaN, a pose of norm 2, of 7 numbers, not unit, zero, a
negative gain), and the field each refusal names."""


def test_a_refused_request_is_on_the_status_with_its_reason_and_the_goal_stays(
    deployed: Callable[[str], System],
) -> None:
    """Each request in turn, to one supervisor whose goal is under way: each is refused, the
    status names its field, and the goal goes on (its phase kept, status after status)."""
    operator = supervised(deployed)
    goal = operator.robot.fkm(REACH_GOAL)
    operator.ask(goal)
    operator.send_state(REACH_GOAL)
    operator.statuses.wait_for(lambda s: s.phase not in ("idle", "planning"), "the goal taken")
    for refusals, (fields, blamed) in enumerate(REFUSED_REQUESTS, start=1):
        operator.ask_raw(fields)
        refused = refusal(operator, refusals)
        assert f"Goal.{blamed}" in refused.last_refusal, (fields, refused.last_refusal)
        assert refused.phase not in ("idle", "planning", "unreachable"), refused
        after = operator.status_answering(REACH_GOAL, "a status after the refusal")
        assert after.phase == refused.phase and after.refusals == refusals


def refusal(operator: Operator, refusals: int) -> SupervisorStatus:
    """The first status that counts ``refusals`` refused requests."""
    return operator.statuses.wait_for(lambda s: s.refusals == refusals, f"refusal {refusals}")


@pytest.mark.parametrize(
    "task",
    [
        PoseTask(MODEL.fkm(REACH_GOAL)),
        PositionTask(np.array([0.5, -0.2, 0.3])),
        PointTask(np.array([0.4, -0.2]), np.array([0.0, -0.3, 0.2, 0.0, 0.4]), 0.03),
        HeadingTask(-2.5, np.array([0.0, -0.3, 0.2, 0.0, 0.4]), np.array([0.3, 0.1])),
    ],
)
def test_the_goal_of_every_task_kind_asks_for_that_task(task) -> None:
    header = Header(stamp_ns=1, frame="world", seq=0, source="test")
    back = task_of(codec.decode(codec.encode(goal_of(task, header)), Goal))
    assert type(back) is type(task) and same_task(back, task)


def test_status_queries_are_answered_while_a_plan_runs_on_the_planner_thread(
    deployed: Callable[[str], System],
) -> None:
    """A goal walled off by a ring of 30 posts: the plan tries every start of every joint
    margin before it finds no way in (72 starts, 0.56 s of CPU time). The launcher's status query is
    answered by the handler thread meanwhile, before the plan comes back, and the plan's
    verdict follows with its reason."""
    operator = supervised(deployed)
    ring = tuple(
        Circle(x=2.0 + 0.9 * math.cos(a), y=0.9 * math.sin(a), radius=0.08)
        for a in np.linspace(0.0, 2.0 * math.pi, 30, endpoint=False)
    )
    take_obstacles(operator, ring)
    asked = operator.ask(operator.robot.fkm(np.array([2.0, 0.0, 0.0, 0.0, -0.3, -0.4, 0.2, 0.3])))
    operator.answer_to(asked, HOME, "the goal taken")
    operator.statuses.wait_for(lambda s: s.phase == "planning", "the plan handed over")
    answer = component_status(operator.system, "supervisor")
    assert answer is not None, "no answer to the status query while the plan ran"
    assert answer.counters["plans"] == 0 and answer.counters["unreachable"] == 0
    verdict = operator.statuses.wait_for(lambda s: s.phase == "unreachable", "the plan's verdict")
    assert "no way round the obstacles" in verdict.reason, verdict.reason
    after = component_status(operator.system, "supervisor")
    assert after is not None and after.counters["unreachable"] == 1


@pytest.mark.parametrize("kind", ["PositionTask", "PointTask", "HeadingTask"])
def test_a_goal_of_every_kind_has_a_status_with_every_state_until_and_after_it_is_reached(
    deployed: Callable[[str], System], kind: str
) -> None:
    """A position goal is passed on to the controller as it is: the status stopped there (its
    counter stuck at 1501, `topic echo --count 1` hung). Each state now brings a status,
    ``direct`` with the task's error, then ``reached``, and statuses go on after it."""
    operator = supervised(deployed)
    goal = met_at(REACH_GOAL)[kind]
    asked = operator.send_goal(goal)
    operator.answer_to(asked, HOME, "the goal taken")
    direct = operator.statuses.wait_for(lambda s: s.phase == "direct", "the goal's first status")
    assert direct.error_norm is not None and direct.error_norm > 0.01
    passed = operator.goals.wait_for(lambda g: g.task == goal.task, "the goal passed on")
    assert passed.model_dump(exclude={"header"}) == goal.model_dump(exclude={"header"})
    reached = operator.status_answering(REACH_GOAL, "the status of the goal met")
    assert reached.phase == "reached" and reached.error_norm < 1e-9, reached
    for _ in range(3):
        after = operator.status_answering(REACH_GOAL, "one more")
        assert after.phase == "reached"
    # The component's own state says the phase too: the launcher prints its every change.
    namespace = operator.system.profile.namespace
    assert status_of(operator.system.router, namespace, "supervisor").state == "reached"


def test_an_invalid_state_aborts_the_goal_refuses_new_ones_and_the_status_says_why(
    deployed: Callable[[str], System],
) -> None:
    """In a soak the state went invalid (no camera fix) and the supervisor went silent for
    865 s, ignoring 88 goals with no word. Now every invalid state brings a status that says
    why and since when; the goal under way is aborted, a new one refused with that reason,
    and when the state is valid again the robot is held where it stands, not sent on."""
    operator = supervised(deployed)
    asked = operator.ask(operator.robot.fkm(REACH_GOAL))
    operator.answer_to(asked, HOME, "the goal taken")
    operator.statuses.wait_for(lambda s: s.phase not in ("idle", "planning"), "the plan")
    aborted = operator.status_answering(HOME, "the abort", valid=False, age_s=12.0)
    assert aborted.phase == "aborted" and aborted.state == "invalid", aborted
    assert aborted.no_fix_s == 12.0 and aborted.state_since_s is not None
    assert "no valid robot state for 0.0 s (no camera fix of the base for 12.0 s)" in (
        aborted.reason
    ), aborted.reason
    goals = len(operator.goals.messages)
    for _ in range(3):
        later = operator.status_answering(HOME, "a later status", valid=False, age_s=13.0)
        assert later.phase == "aborted" and later.no_fix_s == 13.0
    asked = operator.ask(operator.robot.fkm(REACH_GOAL))
    refused = operator.answer_to(asked, HOME, "the refusal", valid=False, age_s=14.0)
    assert refused.phase == "refused" and refused.refusals == 1, refused
    assert refused.reason == refused.last_refusal and "no camera fix of the base for 14.0 s" in (
        refused.reason
    )
    assert len(operator.goals.messages) == goals  # nothing for the controller meanwhile
    back = operator.status_answering(REACH_GOAL, "valid again")
    assert back.phase == "refused" and back.state == "valid"
    hold = operator.goals.wait_for(lambda g: operator.goals.messages.index(g) >= goals, "hold")
    assert hold.task == "point"
    np.testing.assert_allclose(hold.arm, REACH_GOAL[3:])


def test_a_plan_round_256_circles_keeps_to_its_cpu_budget_and_says_it_ran_out(
    deployed: Callable[[str], System],
) -> None:
    """256 circles, an obstacles message's limit: building the way's graph alone took 3.3 to
    4.8 s of CPU past the budget, and one plan 17.1 s of wall time. The whole plan now keeps
    to the budget (CPU time: the machine's load does not count), and the status says why the
    goal is unreachable."""
    system = yaml.safe_load(PROFILE)
    system["components"][0]["params"] = {"planning_budget_s": 0.5}
    operator = supervised(deployed, yaml.safe_dump(system))
    goal = operator.robot.fkm(REACH_GOAL)
    x, y = dq.translation(goal)[1:3]
    take_obstacles(
        operator,
        tuple(Circle(x=cx, y=cy, radius=r) for cx, cy, r in crowd(((HOME[0], HOME[1]), (x, y)))),
    )
    asked = operator.ask(goal)
    operator.answer_to(asked, HOME, "the goal taken")
    verdict = operator.statuses.wait_for(
        lambda s: s.phase == "unreachable", "the verdict", timeout_s=60.0
    )
    assert "planning budget of 0.5 s of CPU time" in verdict.reason, verdict.reason
    assert verdict.planning_cpu_ms is not None
    assert verdict.planning_cpu_ms <= 500.0 + 1e3 * CHECK_GAP_S, verdict.planning_cpu_ms


def test_goals_that_would_take_the_base_out_of_the_cameras_sight_are_turned_down(
    deployed: Callable[[str], System],
) -> None:
    """With the scene's ceiling camera (here right above F0, where the test's states put the
    robot), a position goal whose target it cannot see is refused, a pose goal whose every
    configuration stands out of its sight is unreachable for that reason, and one it sees is
    planned with the base, staging point and way in sight."""
    system = yaml.safe_load(PROFILE)
    scene = read_profile_data(DEPLOY / "sim.yaml")["scene"]
    system["scene"] = {**scene, "reference_pose": [*scene["camera"]["position"][:2], 0.0]}
    operator = supervised(deployed, yaml.safe_dump(system))
    region = sight_region(operator.system.profile.scene)
    assert region and within(region, HOME[:2])
    out_of_sight = np.concatenate(([3.5, 0.0, 0.0], REACH_GOAL[3:]))
    assert not within(region, out_of_sight[:2])
    target = dq.translation(operator.robot.fkm(out_of_sight))[1:]
    asked = operator.send_goal(Goal(header=header(), task="position", position=tuple(target)))
    refused = operator.answer_to(asked, HOME, "the refusal")
    assert refused.phase == "refused" and "the camera cannot see the base" in refused.reason
    status = unreachable(operator, operator.robot.fkm(out_of_sight), "cannot see it")
    assert "take the base where the camera cannot see it" in status.reason, status.reason
    asked = operator.ask(operator.robot.fkm(REACH_GOAL))
    operator.answer_to(asked, HOME, "the goal in sight taken")
    drive = operator.statuses.wait_for(
        lambda s: s.request_stamp_ns == asked and (s.plans == 1 or s.phase == "unreachable"),
        "the plan in sight, or its verdict",
    )
    assert drive.phase != "unreachable", drive.reason
    assert drive.candidate_base is not None and within(region, *drive.way, drive.candidate_base)


def test_with_no_state_the_status_still_goes_out_says_so_and_a_goal_is_refused(
    deployed: Callable[[str], System],
) -> None:
    """`topic echo supervisor/status --count 1` hung once the statuses stopped: they go out
    every half second while no state comes, and a goal that no state follows is refused."""
    operator = supervised(deployed)
    operator.ask(operator.robot.fkm(REACH_GOAL))
    refused = operator.statuses.wait_for(lambda s: s.phase == "refused", "the refusal")
    assert refused.state == "none" and "no robot state on robot/state for" in refused.reason
    count = len(operator.statuses.messages)
    later = operator.statuses.wait_for(
        lambda s: operator.statuses.messages.index(s) > count, "two statuses more, with no state"
    )
    assert later.phase == "refused" and later.state == "none"


def test_a_position_goal_too_far_is_refused_in_a_few_words_and_statuses_go_on(
    deployed: Callable[[str], System],
) -> None:
    """A position goal at 1e300 m: its error is no float a status can carry; it is refused
    like a pose goal that far, in a short reason, and the statuses go on."""
    operator = supervised(deployed)
    asked = operator.send_goal(Goal(header=header(), task="position", position=(1e300, 0.0, 0.3)))
    refused = operator.answer_to(asked, HOME, "the refusal")
    assert refused.phase == "refused" and len(refused.reason) < 120, refused.reason
    assert "farther than the 10 m a goal may lie" in refused.reason, refused.reason
    after = operator.status_answering(HOME, "one more")
    assert after.phase == "refused"
    # Held where it stands: the controller's goal travels apart from the status, maybe later.
    operator.goals.wait_for(lambda g: g.task == "point", "the hold")
    assert all(g.task == "point" for g in operator.goals.messages), operator.goals.messages
