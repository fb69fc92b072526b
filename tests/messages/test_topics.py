"""The topic table and the key expressions it spells."""

from __future__ import annotations

import pytest
import zenoh
from hypothesis import given
from hypothesis import strategies as st

from messages import (
    MESSAGE_TYPES,
    ROBOT_STATE,
    SIM_CLOCK,
    TOPICS,
    ComponentStatus,
    KeyExpressionError,
    RobotState,
    component_of_liveliness_key,
    component_of_status_key,
    key,
    liveliness_key,
    liveliness_selector,
    namespace_selector,
    param_key,
    param_selector,
    status_key,
    status_selector,
    topic_of_key,
)
from messages.base import Message
from messages.topics import all_params_selector, param_of_key

NAMESPACE = "lab/robot1"

chunks = st.text(
    alphabet=st.characters(
        codec="ascii", categories=("L", "N"), include_characters="_-.", exclude_characters="$"
    ),
    min_size=1,
    max_size=10,
)
namespaces = st.lists(chunks, min_size=1, max_size=3).map("/".join)

BAD_NAMESPACES = ["", "/sim", "sim/", "a//b", "sim/*", "sim/**", "$*", "a#b", "a?b", "s$m"]


def _includes(selector: str, key_expr: str) -> bool:
    return zenoh.KeyExpr(selector).includes(zenoh.KeyExpr(key_expr))


def test_the_table_holds_every_topic_of_the_design() -> None:
    assert {name: topic.type.__name__ for name, topic in TOPICS.items()} == {
        "camera/image": "CameraFrame",
        "vision/markers": "MarkerDetections",
        "base/odometry": "BaseOdometry",
        "arm/joint_states": "JointStates",
        "robot/state": "RobotState",
        "world/obstacles": "Obstacles",
        "world/markers": "MarkerDetections",
        "control/goal": "Goal",
        "goal/request": "Goal",
        "world/goal": "Goal",
        "supervisor/status": "SupervisorStatus",
        "base/command": "BaseCommand",
        "arm/command": "ArmCommand",
        "control/diagnostics": "ControllerDiagnostics",
        "sim/clock": "Clock",
        "sim/truth": "SimTruth",
        "control/stop": "StopState",
        "teleop/command": "TeleopCommand",
    }


def test_every_topic_carries_a_message_type() -> None:
    for topic in TOPICS.values():
        assert issubclass(topic.type, Message)
        assert topic.type in MESSAGE_TYPES
    assert ComponentStatus in MESSAGE_TYPES


def test_suffixes_are_distinct() -> None:
    suffixes = [topic.suffix for topic in TOPICS.values()]
    assert len(set(suffixes)) == len(suffixes)


def test_constants_are_the_table_entries() -> None:
    assert TOPICS["robot/state"] is ROBOT_STATE
    assert ROBOT_STATE.type is RobotState
    assert SIM_CLOCK.key("sim") == "sim/sim/clock"


@given(namespace=namespaces)
def test_every_key_is_a_concrete_zenoh_key_under_the_namespace(namespace: str) -> None:
    for name, topic in TOPICS.items():
        topic_key = topic.key(namespace)
        assert topic_key == key(namespace, topic) == key(namespace, name)
        assert topic_key == f"{namespace}/{topic.suffix}"
        zenoh.KeyExpr(topic_key)  # raises ZError on an invalid key
        assert _includes(namespace_selector(namespace), topic_key)
        assert topic_of_key(namespace, topic_key) is topic


def test_two_namespaces_do_not_overlap() -> None:
    assert not _includes(namespace_selector("robot1"), ROBOT_STATE.key("robot2"))
    assert not _includes(liveliness_selector("robot1"), liveliness_key("robot10", "sim2d"))


@pytest.mark.parametrize("namespace", BAD_NAMESPACES)
def test_key_refuses_a_namespace_with_wildcards_or_bad_slashes(namespace: str) -> None:
    with pytest.raises(KeyExpressionError):
        key(namespace, ROBOT_STATE)
    with pytest.raises(KeyExpressionError):
        liveliness_key(namespace, "sim2d")


def test_key_expression_error_is_a_value_error() -> None:
    assert issubclass(KeyExpressionError, ValueError)


def test_an_unknown_topic_name_is_refused_with_the_known_ones() -> None:
    with pytest.raises(KeyExpressionError, match="robot/state"):
        key("sim", "robot/status")


def test_a_key_outside_the_table_has_no_topic() -> None:
    with pytest.raises(KeyExpressionError):
        topic_of_key("sim", "sim/robot/pose")
    with pytest.raises(KeyExpressionError):
        topic_of_key("sim", "other/robot/state")


@given(namespace=namespaces, component=chunks)
def test_liveliness_key_round_trips(namespace: str, component: str) -> None:
    token = liveliness_key(namespace, component)
    assert token == f"{namespace}/alive/{component}"
    assert _includes(liveliness_selector(namespace), token)
    assert component_of_liveliness_key(namespace, token) == component


@given(namespace=namespaces, component=chunks)
def test_status_key_round_trips(namespace: str, component: str) -> None:
    status = status_key(namespace, component)
    assert status == f"{namespace}/component/{component}/status"
    assert _includes(status_selector(namespace), status)
    assert component_of_status_key(namespace, status) == component


@pytest.mark.parametrize("component", ["", "a/b", "*", "lp$", "x?"])
def test_component_names_are_one_plain_chunk(component: str) -> None:
    with pytest.raises(KeyExpressionError):
        liveliness_key("sim", component)
    with pytest.raises(KeyExpressionError):
        status_key("sim", component)


@pytest.mark.parametrize(
    "token", ["sim/alive/a/b", "sim/alive/", "other/alive/lp", "sim/component/lp/status"]
)
def test_a_key_that_is_no_liveliness_token_is_refused(token: str) -> None:
    with pytest.raises(KeyExpressionError):
        component_of_liveliness_key("sim", token)


def test_a_key_that_is_no_status_key_is_refused() -> None:
    with pytest.raises(KeyExpressionError):
        component_of_status_key("sim", "sim/component/lp/param/eta")


def test_param_keys_sit_under_their_component() -> None:
    assert param_key("sim", "lp_controller", "eta") == "sim/component/lp_controller/param/eta"
    assert param_key("sim", "lp", "gains/beta") == "sim/component/lp/param/gains/beta"
    assert _includes(param_selector("sim", "lp"), param_key("sim", "lp", "gains/beta"))
    assert not _includes(param_selector("sim", "lp"), param_key("sim", "cascade", "eta"))
    with pytest.raises(KeyExpressionError):
        param_key("sim", "lp", "*")


def test_every_components_parameters_are_selected_and_named_back() -> None:
    key = param_key("sim", "lp", "gains/beta")
    assert _includes(all_params_selector("sim"), key)
    assert _includes(all_params_selector("sim"), param_key("sim", "cascade", "eta"))
    assert not _includes(all_params_selector("sim"), status_key("sim", "lp"))
    assert param_of_key("sim", key) == ("lp", "gains/beta")
    with pytest.raises(KeyExpressionError):
        param_of_key("sim", status_key("sim", "lp"))
