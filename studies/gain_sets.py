"""The experiments' gain sets: the LP law's gains of each experiment of section 6.2 (and of the
reach over a table), declared once, with the reasons beside; the commands, the studies and the
tests of ``wbc`` take them from here."""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import replace
from typing import Any

from profiles.deploy_files import DEPLOY
from profiles.profile import load_profile
from wbc.laws.lp_law import LPParams, default_objectives
from wbc.laws.objectives.input_change import InputChangeGains

OBSTACLE_PARAMS = LPParams(
    base_target=0.0, waist_hold=0.0, waist_centring=0.02, error_bound="error"
)
"""The obstacle experiment's law (6.2.3): the default obstacle constraint, the vector-field
inequality of wbc.laws.constraints.obstacle_vector_field, in place of 5.28 (the study
studies/files/obstacles.yaml compares them), the circulation term that takes the base round an
obstacle it stalled by, and no base target term, whose straight-line heading towards where the
base should stand fights the detour. The waist is centred through the self-motion instead of
held: with the base alone taking the task's yaw, the base overran the goal after its detour
(error 0.18 after 80 s); the self-motion costs an entry (figure 6.17 shows 8 in use; this law
uses 7 in most steps and never 8, ``parsimony reproduce``'s ``obstacle.entries.LP``).
||u||_1 is bounded by the error (5.7), not by its rate (5.10): when the base stands still by
the obstacle, e' is 0, 5.10 allows no motion at all and the circulation could not start it
again (seed 1: error 0.65 after 60 s)."""

BORDER_PARAMS = replace(OBSTACLE_PARAMS, obstacle_mode="border")
"""The same law with the border constraint 5.28 in place of the vector-field inequality, for
comparison: its circulation term, 5.7 and the point 0.1 m ahead of the axle kept, so not 5.29
as written (``bare_5_29`` is)."""

SUPERVISED_PROFILE = DEPLOY / "sim_supervised.yaml"
"""The profile of the LP under the staging supervisor, which declares that LP's gains."""


@functools.cache
def supervised_params() -> LPParams:
    """The LP law's gains under the staging supervisor (wbc.planning.staging_supervisor), as
    ``SUPERVISED_PROFILE`` gives its controller (declared there once, the reasons beside)."""
    controller = load_profile(SUPERVISED_PROFILE).component("controller")
    return LPParams(
        **{
            f.name: controller.params[f.name]
            for f in dataclasses.fields(LPParams)
            if f.name in controller.params
        }
    )


POSE_PARAMS = LPParams(eta=0.6, beta=15.0)
"""The LP law's gains of the pose experiment (6.2.1 gives eta 0.6 and beta 15)."""
TABLE_PARAMS = POSE_PARAMS
"""Reaching over a table (future work 3 of 7.2): the pose experiment's law, whose rows of
wbc.laws.constraints.arm_obstacles keep the arm and the base clear of the table."""
WITHOUT_ARM_ROWS = replace(TABLE_PARAMS, arm_obstacles=False)
"""The same law blind to the table, for comparison."""

SMOOTH_PROFILE = DEPLOY / "sim_smooth.yaml"
"""The profile of the LP with its input change term on, which declares that term's gains."""


@functools.cache
def input_change_gains() -> dict[str, Any]:
    """The input change term's gains (wbc.laws.objectives.input_change) as ``SMOOTH_PROFILE`` gives
    its controller: what turns the term on in any LPParams (``dataclasses.replace``)."""
    controller = load_profile(SMOOTH_PROFILE).component("controller")
    return {f.name: controller.params[f.name] for f in dataclasses.fields(InputChangeGains)}


LP_PARAMS = {
    "pose": POSE_PARAMS,
    "position": LPParams(eta=1.0, beta=10.0),
    "obstacle": OBSTACLE_PARAMS,
    "table": TABLE_PARAMS,
}
"""The LP law's gains in each experiment of section 6.2; an experiment under the supervisor
takes its profile's (``supervised_params``)."""

BARE = dict(
    velocity_cost=0.0,
    waist_hold=0.0,
    waist_centring=0.0,
    obstacle_circulation=0.0,
    base_target=0.0,
    input_change=0.0,
    arm_obstacles=False,
    obstacle_mode="border",
    obstacle_lookahead=0.0,
    error_bound="derivative",
)
"""What turns an LPParams into 5.29 as the dissertation writes it: no term beside the task
residual, 5.28 on the axle centre (d = 0), 5.10, no rows of this project's."""


def bare_5_29(params: LPParams) -> LPParams:
    """``params`` (its eta, beta, k, b_l) with ``BARE``: the program of 5.29 and nothing else."""
    bare = replace(params, **BARE)
    assert not default_objectives(bare), default_objectives(bare)  # a new term must join BARE
    return bare
