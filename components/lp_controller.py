"""The parsimonious controller as a process: the LP law of chapter 5 (``wbc.lp_law``).

Run as ``python -m components.lp_controller --profile P --name N``; everything but the
law and its parameters is the controller shell of ``components.controller``.
"""

from __future__ import annotations

from components.controller import CONTROLLER_PARAMS, Controller
from components.params import Param
from components.runtime import run_component
from wbc.lp_law import LPLaw, LPParams


class LPController(Controller):
    """u = argmin ||J u + eta e||_1 under the constraints of 5.29, one LP per robot/state."""

    law_name = "lp"
    law_type = LPLaw
    gains_type = LPParams
    params = (
        Param("eta", float, LPParams.eta, low=1e-3, high=100.0, doc="task gain, 1/s"),
        Param("beta", float, LPParams.beta, low=1e-3, high=1e3, doc="bound gain of 5.10"),
        Param("joint_gain", float, LPParams.joint_gain, low=1e-3, high=100.0, doc="k of 5.14"),
        Param("safety_factor", float, LPParams.safety_factor, low=0.01, high=1.0, doc="5.14"),
        Param(
            "error_bound",
            str,
            LPParams.error_bound,
            choices=("derivative", "error"),
            doc="5.10 (derivative) or 5.7 (error)",
        ),
        Param(
            "obstacle_mode",
            str,
            LPParams.obstacle_mode,
            choices=("border", "conservative", "off"),
            doc="obstacle constraint: 5.28 (border), 5.19 (conservative) or none",
        ),
        Param("velocity_cost", float, LPParams.velocity_cost, low=0.0, high=1.0, doc="tie-break w"),
        Param("waist_centring", float, LPParams.waist_centring, low=0.0, high=1.0,
              doc="weight of |q1' + k q1| (0: off)"),
        Param("base_target", float, LPParams.base_target, low=0.0, high=1.0,
              doc="weight of turning the base towards where it should stand (0: off)"),
        *CONTROLLER_PARAMS,
    )


if __name__ == "__main__":
    run_component(LPController)
