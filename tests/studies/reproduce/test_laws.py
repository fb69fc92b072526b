"""What each law `parsimony reproduce` runs says it ran (studies/reproduce/laws.py), read from
the law object itself."""

from __future__ import annotations

from profiles.deploy_files import ROBOT_FILE
from studies.reproduce.laws import describe, speed_bounds
from wbc.geometry.obstacles import Circle
from wbc.laws.cascade_law import CascadeLaw, CascadeParams
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.laws.pinv_law import PinvParams, PseudoinverseLaw
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)


def test_the_lp_names_its_rows_and_terms_and_the_obstacle_rows_only_with_obstacles() -> None:
    law = LPLaw(ROBOT, LPParams(beta=15.0))
    alone = describe(law)
    assert alone.startswith("min ||J u + eta e||_1, eta 0.6, subject to 5.12; 5.15 (k 1")
    assert speed_bounds(ROBOT) in alone and "5.10 (beta 15)" in alone
    assert "vector-field" not in alone and "obstacle_circulation" not in alone
    near = describe(law, (Circle(1.0, 0.0, 0.2),))
    assert "the vector-field inequality d' >= -2 d in place of 5.28" in near


def test_the_pseudoinverse_and_the_cascade_say_they_bound_nothing_unless_saturated() -> None:
    assert describe(PseudoinverseLaw(ROBOT)).endswith(
        "holonomic base (5.3), eta 0.6; no bound on u"
    )
    assert "of J N" in describe(PseudoinverseLaw(ROBOT, PinvParams(nonholonomic=True)))
    assert describe(CascadeLaw(ROBOT)).endswith("no bound on u")
    saturated = describe(CascadeLaw(ROBOT, CascadeParams(saturate=True)))
    assert f"saturated: (v, phi') scaled into {speed_bounds(ROBOT)}" in saturated
