"""The experiments' gain sets: the profiles' gains read as the profiles declare them, and 5.29 as
written keeping a law's gains and nothing beside the task."""

from __future__ import annotations

import dataclasses

from profiles.deploy_files import DEPLOY
from profiles.profile import load_profile
from studies.gain_sets import (
    LP_PARAMS,
    bare_5_29,
    input_change_gains,
    supervised_params,
)
from wbc.laws.constraints.error_bound import ErrorBound
from wbc.laws.constraints.obstacle_border import BorderObstacle
from wbc.laws.lp_law import default_constraints, default_objectives
from wbc.laws.objectives.input_change import InputChange


def test_the_supervised_gains_are_those_its_profile_gives_its_controller() -> None:
    controller = load_profile(DEPLOY / "sim_supervised.yaml").component("controller")
    params = supervised_params()
    declared = {f.name for f in dataclasses.fields(params)} & controller.params.keys()
    assert declared
    assert all(getattr(params, name) == controller.params[name] for name in declared)


def test_the_input_change_gains_turn_the_term_on_in_any_law() -> None:
    for params in LP_PARAMS.values():
        assert not any(isinstance(t, InputChange) for t in default_objectives(params))
        smooth = dataclasses.replace(params, **input_change_gains())
        assert any(isinstance(t, InputChange) for t in default_objectives(smooth))


def test_5_29_as_written_keeps_the_gains_and_nothing_beside_the_task() -> None:
    obstacle = LP_PARAMS["obstacle"]
    bare = bare_5_29(obstacle)
    assert (bare.eta, bare.beta) == (obstacle.eta, obstacle.beta)
    assert default_objectives(bare) == []
    kinds = {type(c) for c in default_constraints(bare)}
    assert BorderObstacle in kinds and ErrorBound in kinds
    assert bare.error_bound == "derivative" and bare.obstacle_lookahead == 0.0
