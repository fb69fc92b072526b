"""Declared parameters: types, bounds, choices, text parsing and profile overrides."""

from __future__ import annotations

import math

import pytest

from components.arm_driver import ArmDriver
from components.params import Param, ParamError, Parameters
from components.scripted_publisher import ScriptedPublisher
from messages.process import decode_value, encode_value
from profiles.deploy_files import DEPLOY
from profiles.profile import load_profile

RATE = Param("rate_hz", float, 10.0, low=0.1, high=100.0)
TASK = Param("task", str, "pose", choices=("pose", "position"))
ENABLED = Param("enabled", bool, True)
STEPS = Param("steps", int, 3, low=1)


@pytest.mark.parametrize(
    ("param", "value", "expected"),
    [
        (RATE, 5, 5.0),
        (RATE, 0.1, 0.1),
        (STEPS, 7, 7),
        (ENABLED, False, False),
        (TASK, "position", "position"),
    ],
)
def test_valid_values_are_accepted_with_their_declared_type(
    param: Param, value: object, expected: object
) -> None:
    checked = param.check(value)
    assert checked == expected and type(checked) is param.type


@pytest.mark.parametrize(
    ("param", "value", "message"),
    [
        (RATE, 0.0, "rate_hz: expected a float in [0.1, 100.0], got 0.0"),
        (RATE, math.nan, "rate_hz: expected a float in [0.1, 100.0], got nan"),
        (RATE, True, "got True"),
        (RATE, "5", "got '5'"),
        (STEPS, 2.0, "steps: expected a int >= 1, got 2.0"),
        (STEPS, 0, "steps: expected a int >= 1, got 0"),
        (ENABLED, 1, "enabled: expected a bool, got 1"),
        (TASK, "dance", "task: expected a str in {'pose', 'position'}, got 'dance'"),
    ],
)
def test_wrong_types_and_out_of_bounds_values_say_what_was_expected(
    param: Param, value: object, message: str
) -> None:
    with pytest.raises(ParamError) as error:
        param.check(value)
    assert message in str(error.value)


@pytest.mark.parametrize(
    ("param", "text", "value"),
    [
        (RATE, " 2.5 ", 2.5),
        (STEPS, "4", 4),
        (ENABLED, "off", False),
        (ENABLED, "True", True),
        (TASK, "position", "position"),
    ],
)
def test_text_values_parse_to_the_declared_type(param: Param, text: str, value: object) -> None:
    assert param.parse(text) == value


@pytest.mark.parametrize(("param", "text"), [(RATE, "fast"), (STEPS, "1.5"), (ENABLED, "maybe")])
def test_unparsable_text_is_refused(param: Param, text: str) -> None:
    with pytest.raises(ParamError, match=f"got '{text}'"):
        param.parse(text)


def test_a_bad_default_is_refused_at_declaration() -> None:
    with pytest.raises(ParamError, match="beta: expected a float >= 0.0"):
        Param("beta", float, -1.0, low=0.0)


def test_profile_overrides_replace_defaults_and_unknown_names_are_refused() -> None:
    params = Parameters([RATE, TASK], {"rate_hz": 20})
    assert dict(params) == {"rate_hz": 20.0, "task": "pose"}
    assert params.set_text("task", "position") == "position" and params["task"] == "position"
    with pytest.raises(ParamError, match="gain: unknown parameter; declared: rate_hz, task"):
        Parameters([RATE, TASK], {"gain": 1.0})
    with pytest.raises(ParamError, match="unknown parameter 'gain'"):
        params.set_text("gain", "1")


@pytest.mark.parametrize("value", [True, 3, 2.5, "pose"])
def test_reply_values_round_trip_with_their_type(value: object) -> None:
    decoded = decode_value(encode_value(value))
    assert decoded == value and type(decoded) is type(value)


@pytest.mark.parametrize("controller", ["lp_controller", "cascade_controller"])
def test_every_gain_of_a_law_is_a_parameter_with_the_bounds_its_dataclass_declares(controller):
    import importlib

    from wbc.laws.gains import gain_specs

    module = importlib.import_module(f"components.{controller}")
    component = next(
        v for v in vars(module).values() if isinstance(v, type) and v.__module__ == module.__name__
    )
    declared = {param.name: param for param in component.params}
    for spec in gain_specs(component.gains_type):
        param = declared[spec.name]
        assert (param.type, param.default, param.low, param.high, param.choices, param.doc) == (
            spec.type,
            spec.default,
            spec.low,
            spec.high,
            spec.choices,
            spec.doc,
        )
        if spec.high is not None:
            with pytest.raises(ParamError, match=spec.name):
                param.check(spec.high * 2 + 1)


def test_the_arm_drivers_servo_ids_are_distinct_integers_or_none_and_say_so() -> None:
    """One per joint of the robot (checked where the driver loads it); [] keeps the robot
    description's servos.ids."""
    ids = Parameters(ArmDriver.params, {"ids": [5, 4, 3, 2, 1]})["ids"]
    assert ids == (5, 4, 3, 2, 1) and all(type(i) is int for i in ids)
    assert Parameters(ArmDriver.params, {}).set_text("ids", "[1, 2, 3, 4, 6]") == (1, 2, 3, 4, 6)
    assert Parameters(ArmDriver.params, {})["ids"] == ()
    expected = "ids: expected 1 or more integers in a list, or [] for none"
    for value, message in [
        ("1, 2, 3, 4, 5", f"{expected}, got '1, 2, 3, 4, 5'"),
        ([1, 2, 3, 4, 5.0], expected),
        ([1, 1, 2, 3, 4], "ids: expected distinct servo ids in 0..253, got (1, 1, 2, 3, 4)"),
        ([1, 2, 3, 4, 254], "ids: expected distinct servo ids in 0..253"),
    ]:
        with pytest.raises(ParamError) as error:
            Parameters(ArmDriver.params, {"ids": value})
        assert message in str(error.value)


def test_the_scripted_goal_pose_is_eight_numbers_or_none() -> None:
    assert Parameters(ScriptedPublisher.params, {})["goal_pose"] == ()
    pose = Parameters(ScriptedPublisher.params, {"goal_pose": [1, 0, 0, 0, 0, 0, 0, 0.5]})
    assert pose["goal_pose"] == (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.5)
    assert pose.set_text("goal_pose", "[]") == ()
    for value in ("1, 0, 0, 0, 0, 0, 0, 0", [1, 0, 0, 0, 0, 0, 0], [math.nan] * 8):
        with pytest.raises(ParamError, match="goal_pose: expected 8 finite numbers in a list, or"):
            Parameters(ScriptedPublisher.params, {"goal_pose": value})


@pytest.mark.parametrize(
    ("profile", "name", "component", "param", "length"),
    [
        ("controllers.yaml", "publisher", ScriptedPublisher, "goal_pose", 8),
    ],
)
def test_the_profiles_that_set_a_vector_load_it_typed(
    profile: str, name: str, component: type, param: str, length: int
) -> None:
    spec = load_profile(DEPLOY / profile).component(name)
    value = Parameters(component.params, spec.params)[param]
    assert isinstance(value, tuple) and len(value) == length
