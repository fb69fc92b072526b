"""What the supervisor knows of the robot state (components.robot_sight): none until a state
and again after ``timeout_s`` without one, valid, degraded (odometry alone, said as a warning)
or invalid (why, in words), each since the stamp of the first state so."""

from __future__ import annotations

from components.robot_sight import RobotSight, sight_region
from messages.base import IDENTITY_POSE
from messages.header import Header
from messages.state import RobotState

S = 1_000_000_000
"""Nanoseconds a second."""


def state(stamp_s: float, valid: bool = True, degraded: bool = False, age_s: float = 0.0):
    return RobotState(
        header=Header(stamp_ns=int(stamp_s * S), frame="world", seq=0, source="test"),
        base_pose=(0.0, 0.0, 0.0),
        arm_joints=(0.0,) * 5,
        end_effector=IDENTITY_POSE,
        valid=valid,
        age_s=age_s,
        degraded=degraded,
    )


def test_no_state_yet_is_none_and_says_so() -> None:
    sight = RobotSight(None, timeout_s=0.5)
    assert sight.state(10 * S) == "none"
    assert sight.missing(10 * S) == "no robot state on robot/state yet"
    assert sight.fields(10 * S)["state_since_s"] is None


def test_a_state_is_named_since_the_first_of_its_kind_and_none_after_the_timeout() -> None:
    sight = RobotSight(None, timeout_s=0.5)
    sight.saw(state(1.0))
    sight.saw(state(1.2))
    assert sight.state(int(1.5 * S)) == "valid" and sight.missing(int(1.5 * S)) == ""
    assert sight.fields(int(1.5 * S)) == {
        "state": "valid",
        "state_since_s": 1.0,
        "no_fix_s": None,
        "warning": "",
    }
    assert sight.state(int(1.8 * S)) == "none"  # 0.6 s since the last state
    assert sight.missing(int(1.8 * S)) == "no robot state on robot/state for 0.6 s"
    assert sight.fields(int(1.8 * S))["state_since_s"] == 1.2  # since the last state


def test_a_degraded_state_warns_and_an_invalid_one_says_how_long_without_a_fix() -> None:
    sight = RobotSight(None, timeout_s=0.5)
    sight.saw(state(2.0, degraded=True, age_s=1.5))
    fields = sight.fields(int(2.1 * S))
    assert (fields["state"], fields["no_fix_s"]) == ("degraded", 1.5)
    assert fields["warning"].startswith("the camera has not fixed the base for 1.5 s")
    assert sight.missing(int(2.1 * S)) == ""  # degraded is still a valid state
    sight.saw(state(3.0, valid=False, age_s=2.5))
    sight.saw(state(4.0, valid=False, age_s=3.5))
    assert sight.missing(int(4.2 * S)) == (
        "no valid robot state for 1.2 s (no camera fix of the base for 3.5 s)"
    )
    sight.saw(state(5.0, valid=False, age_s=0.0))
    assert sight.missing(int(5.0 * S)).endswith("(no camera fix of the base yet)")


def test_without_a_scene_the_base_has_no_region_to_keep_to() -> None:
    assert sight_region(None) == ()
