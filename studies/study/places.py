"""What a study's runs run on (its places) and the laws each place takes: the goal families of
``studies.goal_families`` with the laws of ``studies.goal_sets``; the zoo's goals
(``studies.redundancy``) with its laws; an experiment's set-up run kinematically with the
experiment's law; an experiment on the whole simulated loop with a controller of
``studies.experiment``. The checks refuse a sweep naming a place, a law or a gain nobody has,
before anything runs."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from pathlib import Path
from typing import Any

from profiles.profile import ProfileError
from sim2d.scenarios import NAMES
from studies import redundancy
from studies.experiment import PROFILES, Options, law_overrides
from studies.gain_sets import LP_PARAMS
from studies.goal_families import FAMILIES, OBSTACLE_FAMILIES
from studies.goal_sets import STUDY_LAWS
from studies.study.schema import StudyError
from wbc.laws.law_output import Law
from wbc.laws.lp_law import LPLaw
from wbc.robot import MobileManipulator

GOALS, ZOO, SETUP, SIMULATED = "goals", "zoo", "set-up", "simulated"
"""The kinds of place."""
ZOO_FAMILY = "zoo"
"""The zoo's goals (``studies.redundancy.draw``): a family of its own kind."""
SETUPS = ("obstacle",)
"""The experiments whose set-up a kinematic study runs (the LP of ``LP_PARAMS`` on a pose)."""
Maker = Callable[[MobileManipulator], Law]


def kind(loop: str, place: str) -> str:
    """The kind of ``place`` in a study of ``loop``; ``StudyError`` when it is none."""
    if loop == SIMULATED:
        if place in NAMES:
            return SIMULATED
        raise StudyError(f"no experiment {place!r}; known: {'; '.join(NAMES)}")
    if place in FAMILIES or place in OBSTACLE_FAMILIES:
        return GOALS
    if place == ZOO_FAMILY:
        return ZOO
    if place in SETUPS:
        return SETUP
    known = [*FAMILIES, *OBSTACLE_FAMILIES, ZOO_FAMILY, *SETUPS]
    raise StudyError(f"no goal family or experiment set-up {place!r}; known: {'; '.join(known)}")


def makers(kind_: str, place: str) -> dict[str, Maker]:
    """The laws a kinematic place of ``kind_`` takes, by name."""
    if kind_ == GOALS:
        return STUDY_LAWS
    if kind_ == ZOO:
        return redundancy.LAWS
    return {"lp": lambda robot: LPLaw(robot, LP_PARAMS[place])}


def law(kind_: str, place: str, name: str, gains: dict[str, Any], robot: MobileManipulator) -> Law:
    """Law ``name`` of the place with ``gains`` changed (TypeError or ValueError naming a gain
    it has not, or a value it refuses)."""
    made = makers(kind_, place)[name](robot)
    if not gains:
        return made
    return type(made)(robot, dataclasses.replace(made.params, **gains))  # type: ignore[attr-defined]


def check_law(kind_: str, name: str, gains: dict[str, Any], place: str, robot_file: Path) -> None:
    """``StudyError`` unless law ``name`` exists for the place and takes ``gains``."""
    known = list(PROFILES) if kind_ == SIMULATED else list(makers(kind_, place))
    if name not in known:
        loop = "simulated" if kind_ == SIMULATED else "kinematic"
        raise StudyError(f"no {loop} law {name!r} for {place!r}; known: {'; '.join(known)}")
    try:
        if kind_ == SIMULATED:
            law_overrides(Options(name=place, controller=name, gains=gains))
        else:
            law(kind_, place, name, gains, MobileManipulator.from_yaml(robot_file))
    except (TypeError, ValueError, ProfileError) as error:
        raise StudyError(f"law {name!r} with gains {gains}: {error}") from None
