"""view.foxglove_params.checked: a parameter set from a Foxglove client is refused, saying
what is wrong in a few words, before anything of it reaches Zenoh."""

from __future__ import annotations

import pytest
from foxglove import Parameter, ParameterType

from view.foxglove_params import SetRefused, checked

RUNNING = ("controller.eta", "controller.obstacle_mode", "simulator.goal_marker")


def viewer_may_set(component: str) -> str:
    return "" if component == "simulator" else f"viewer may not set {component}'s parameters"


@pytest.mark.parametrize(
    ("parameter", "reason"),
    [
        (
            Parameter("controller." + "x" * 65536, value=1.0),
            "a name of 65547 characters: at most 128",
        ),
        (Parameter("*.eta", value=1.0), "no running component has this parameter"),
        (Parameter("**.eta", value=1.0), "no running component has this parameter"),
        (Parameter("controller/x.eta", value=1.0), "no running component has this parameter"),
        (Parameter("eta", value=1.0), "no running component has this parameter"),
        (
            Parameter("simulator.goal_marker", value=b"\0\1", type=ParameterType.ByteArray),
            "a byte array is no parameter's value",
        ),
        (Parameter("simulator.goal_marker"), "no value given"),
        (
            Parameter("simulator.goal_marker", value="m" * 5000),
            "a value of 5000 characters: at most 4096",
        ),
        (
            Parameter("controller.obstacle_mode", value="off"),
            "viewer may not set controller's parameters",
        ),
    ],
)
def test_a_set_that_cannot_be_sent_is_refused_saying_why(parameter: Parameter, reason: str) -> None:
    with pytest.raises(SetRefused) as refused:
        checked(parameter, RUNNING, viewer_may_set)
    assert str(refused.value).startswith(reason)


def test_a_set_of_a_running_parameter_goes_to_its_component_as_text() -> None:
    assert checked(
        Parameter("simulator.goal_marker", value=[0.6, 0.0]), RUNNING, viewer_may_set
    ) == ("simulator", "goal_marker", "[0.6, 0.0]")
    assert checked(Parameter("controller.eta", value=0.8), RUNNING) == ("controller", "eta", "0.8")
