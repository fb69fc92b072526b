"""A per-joint parameter vector takes any length from its least up (the robot decides the
rest, where the component loads it) and refuses anything else in one line saying what it
expected."""

from __future__ import annotations

import math

import pytest

from components.params import ParamError
from components.robot_vector import RobotVector, of_robot

START = RobotVector("start", tuple, (0.0, 0.0, 0.0), least=3)
IDS = RobotVector("ids", tuple, (), integers=True, optional=True)


@pytest.mark.parametrize("value", [[1, 2, 3], [0.5, -1, 2, 0.25, 7, 8]])
def test_any_length_from_the_least_up_is_taken(value: list[float]) -> None:
    taken = START.check(value)
    assert taken == tuple(float(v) for v in value)


@pytest.mark.parametrize("value", [[1, 2], [], "1, 2, 3", [1, math.nan, 3], [1, "x", 3]])
def test_too_few_or_not_finite_numbers_are_refused_saying_what_was_expected(value) -> None:
    with pytest.raises(ParamError, match="3 or more finite numbers in a list"):
        START.check(value)


def test_an_optional_vector_of_integers_may_be_empty() -> None:
    assert IDS.check([]) == ()
    assert IDS.check([11, 12, 13]) == (11, 12, 13)
    assert IDS.parse("[1, 2]") == (1, 2)


@pytest.mark.parametrize("value", [[1, 2.0], [True, 2], "12"])
def test_an_integer_vector_refuses_floats_bools_and_text(value) -> None:
    with pytest.raises(ParamError, match=r"1 or more integers in a list, or \[\] for none"):
        IDS.check(value)


def test_a_vector_not_the_robots_size_is_refused_naming_its_joints() -> None:
    assert of_robot("ids", (1, 2), 2, "q1, q2") == (1, 2)
    with pytest.raises(ParamError) as refused:
        of_robot("ids", (1, 2, 3), 2, "q1, q2")
    assert str(refused.value) == "ids: expected 2 values (q1, q2), got 3: (1, 2, 3)"
