"""A study's places and the laws each takes: every name a place has is known by its kind, and
a sweep naming a place, a law or a gain nobody has is refused with one ``StudyError`` that
says what is known, before anything runs."""

from __future__ import annotations

import pytest

from profiles.deploy_files import ROBOT_FILE
from studies.gain_sets import LP_PARAMS
from studies.study import places
from studies.study.schema import StudyError
from wbc.laws.lp_law import LPLaw
from wbc.robot import MobileManipulator

KINEMATIC = "kinematic"


@pytest.mark.parametrize(
    ("loop", "place", "kind"),
    [
        (KINEMATIC, "ahead", places.GOALS),
        (KINEMATIC, "anywhere, obstacle", places.GOALS),
        (KINEMATIC, "zoo", places.ZOO),
        (KINEMATIC, "obstacle", places.SETUP),
        (places.SIMULATED, "obstacle", places.SIMULATED),
        (places.SIMULATED, "pose", places.SIMULATED),
    ],
)
def test_each_place_is_of_its_kind(loop: str, place: str, kind: str) -> None:
    assert places.kind(loop, place) == kind


@pytest.mark.parametrize(
    ("loop", "place", "said"),
    [
        (KINEMATIC, "nowhere", "no goal family or experiment set-up 'nowhere'; known: ahead;"),
        (KINEMATIC, "pose", "no goal family or experiment set-up 'pose'"),  # no kinematic set-up
        (places.SIMULATED, "ahead", "no experiment 'ahead'; known: pose; position;"),
    ],
)
def test_a_place_nobody_has_is_refused_naming_the_known(loop: str, place: str, said: str) -> None:
    with pytest.raises(StudyError) as caught:
        places.kind(loop, place)
    assert str(caught.value).startswith(said)


def test_each_kind_takes_its_own_laws() -> None:
    assert {"lp", "qp", "cascade"} <= set(places.makers(places.GOALS, "ahead"))
    assert set(places.makers(places.ZOO, "zoo")) == {"lp", "qp", "pinv"}
    assert list(places.makers(places.SETUP, "obstacle")) == ["lp"]


def test_a_set_up_runs_the_experiments_lp_with_the_gains_changed() -> None:
    robot = MobileManipulator.from_yaml(ROBOT_FILE)
    plain = places.law(places.SETUP, "obstacle", "lp", {}, robot)
    assert isinstance(plain, LPLaw) and plain.params == LP_PARAMS["obstacle"]
    changed = places.law(places.SETUP, "obstacle", "lp", {"eta": 0.25}, robot)
    assert changed.params.eta == 0.25
    assert changed.params.beta == LP_PARAMS["obstacle"].beta  # the others stay the experiment's


def test_check_law_passes_a_law_the_place_has_with_gains_it_takes() -> None:
    places.check_law(places.GOALS, "lp", {"eta": 0.5}, "ahead", ROBOT_FILE)
    places.check_law(places.SIMULATED, "qp", {}, "pose", ROBOT_FILE)


@pytest.mark.parametrize(
    ("kind", "name", "gains", "place", "said"),
    [
        (places.ZOO, "cascade", {}, "zoo", "no kinematic law 'cascade' for 'zoo'; known: lp; qp"),
        (places.SIMULATED, "pinv", {}, "pose", "no simulated law 'pinv' for 'pose'; known: lp;"),
        (places.GOALS, "lp", {"etta": 1.0}, "ahead", "law 'lp' with gains {'etta': 1.0}: "),
        (places.SETUP, "lp", {"eta": -1.0}, "obstacle", "law 'lp' with gains {'eta': -1.0}: "),
        (places.SIMULATED, "lp", {"etta": 1.0}, "pose", "law 'lp' with gains {'etta': 1.0}: no LP"),
        (places.SIMULATED, "lp", {"eta": -1.0}, "pose", "law 'lp' with gains {'eta': -1.0}: gain"),
    ],
)
def test_a_law_or_gain_nobody_has_is_one_study_error(kind, name, gains, place, said) -> None:
    with pytest.raises(StudyError) as caught:
        places.check_law(kind, name, gains, place, ROBOT_FILE)
    assert str(caught.value).startswith(said) and "\n" not in str(caught.value)
