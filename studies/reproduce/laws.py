"""The laws `parsimony reproduce` runs, by label, and what each ran: its rows and terms, said
from the law object itself so the words cannot drift from the run."""

from __future__ import annotations

import dataclasses

import numpy as np

from wbc.geometry.obstacles import Obstacle, split
from wbc.laws.cascade_law import CascadeLaw
from wbc.laws.law_output import Law
from wbc.laws.lp_law import LPLaw, LPParams, default_constraints, default_objectives
from wbc.laws.pinv_law import PseudoinverseLaw
from wbc.laws.qp_law import QPLaw
from wbc.robot import BASE_DOF, MobileManipulator

LP = "LP"
"""The default LP law of each experiment (``studies.gain_sets.LP_PARAMS``)."""
LP_5_29 = "LP 5.29"
"""5.29 as written: every term beside the task at 0 (``studies.gain_sets.bare_5_29``)."""
CASCADE = "cascade"
"""Appendix B as the dissertation ran it: no bound on u. The dissertation's "PINV" of 6.2."""
SATURATED = "cascade, saturated"
"""Appendix B held to the robot's bounds (``CascadeParams.saturate``)."""
CASCADE_LP_TIME = "cascade, LP's time"
"""Appendix B with the eta that converges in the LP's iterations."""
LP_FREE = "LP, no speed bound"
PINV_5_11 = "PINV under 5.11"
QP = "QP"
LP_INPUT_CHANGE = "LP + input change"
LP_BORDER = "LP, 5.28 + circulation + 5.7"
"""The obstacle experiment's law with 5.28 in place of the vector-field inequality."""

UNBOUNDED_SPEED = 1e3
"""The velocity bound of section 6.3's tests, rad/s or m/s: none is stated there, and the
robot's own would hold the LP alone, since neither the classic law nor the cascade has any
(test 2's LP on the robot's bounds ends 2000 iterations at ||e|| 0.094; unbounded it converges
in 76)."""


def speed_bounds(robot: MobileManipulator) -> str:
    """The bounds on u of ``robot`` in words."""
    bounds = robot.velocity_max
    if np.all(bounds >= UNBOUNDED_SPEED):
        return "no speed bound"
    arm = np.unique(bounds[BASE_DOF:])
    arm_text = f"{arm[0]:g}" if len(arm) == 1 else "/".join(f"{b:g}" for b in bounds[BASE_DOF:])
    return (
        f"|x'|, |y'| <= {bounds[0]:g} m/s, |phi'| <= {bounds[2]:g} rad/s, |q'| <= {arm_text} rad/s"
    )


def constraint_text(name: str, p: LPParams, robot: MobileManipulator) -> str:
    """One row group of the program in words, with the equation it writes."""
    ahead = (
        f"on the point {p.obstacle_lookahead:g} m ahead of the axle"
        if p.obstacle_lookahead
        else "on the axle centre"
    )
    reach = f"R = obstacle + body + {p.obstacle_margin:g} m"
    texts = {
        "nonholonomic": "5.12",
        "joint_limits": f"5.15 (k {p.joint_gain:g}, b_l {p.safety_factor:g}; "
        f"{speed_bounds(robot)})",
        "error_derivative_bound": f"5.10 (beta {p.beta:g})",
        "error_bound": f"5.7 (beta {p.beta:g}, on ||e||_1)",
        "obstacle_border": f"5.28 (lambda {p.obstacle_gain:g}, {ahead}, {reach})",
        "obstacle_vector_field": f"the vector-field inequality d' >= -{p.obstacle_gain:g} d in "
        f"place of 5.28 ({ahead}, {reach})",
        "obstacle_conservative": f"5.19 ({reach})",
    }
    return texts.get(name, name)


def describe(law: Law, obstacles: tuple[Obstacle, ...] = ()) -> str:
    """Which law ``law`` is and which rows and terms it ran (the obstacle rows only where
    there are obstacles, the 3-D rows only where there are solids: else they give none)."""
    if isinstance(law, CascadeLaw):
        p = law.params
        bounds = (
            f"saturated: (v, phi') scaled into {speed_bounds(law.robot)} and wheels <= "
            f"{law.robot.base.wheel_speed_max:g} m/s, each joint clipped"
            if p.saturate
            else "no bound on u"
        )
        return (
            f"appendix B: u = -J^+ eta e (B.1), eta {p.eta:.3g}; the base by the "
            f"linearising inner loop (d {p.offset:g} m, k1 {p.k1:g}, k2 {p.k2:g}); "
            f"{bounds}"
        )
    if isinstance(law, PseudoinverseLaw):
        under = (
            "of J N (N spanning what 5.11 allows)"
            if law.params.nonholonomic
            else "holonomic base (5.3)"
        )
        return f"u = -J^+ eta e, {under}, eta {law.params.eta:g}; no bound on u"
    if not isinstance(law, LPLaw | QPLaw):
        return type(law).__name__
    p = law.params
    circles, solids = split(obstacles)
    constraints = getattr(law, "constraints", None)
    constraints = default_constraints(p) if constraints is None else constraints
    objectives = getattr(law, "objectives", None)
    objectives = default_objectives(p) if objectives is None else objectives
    rows = [
        constraint_text(c.name, p, law.robot)
        for c in constraints
        if (c.name != "arm_obstacles" or solids) and (not c.name.startswith("obstacle") or circles)
    ]
    terms = [
        f"{t.name} {getattr(p, dataclasses.fields(type(t).gains[-1])[0].name):g}"
        for t in objectives
        if circles or t.name != "obstacle_circulation"
    ]
    norm = "||J u + eta e||_2^2 (QP)" if isinstance(law, QPLaw) else "||J u + eta e||_1"
    return (
        f"min {norm}, eta {p.eta:g}, subject to {'; '.join(rows) or 'nothing'}; terms "
        f"beside the task: {', '.join(terms) or 'none (5.29 exactly)'}"
    )
