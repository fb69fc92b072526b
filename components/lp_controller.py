"""The parsimonious controller as a process: the LP law of chapter 5 (``wbc.laws.lp_law``).

Run as ``python -m components.lp_controller --profile P --name N``; everything but the
law is the controller shell of ``components.controller``. Every gain of ``LPParams`` is a
run-time parameter with the bounds the dataclass declares.
"""

from __future__ import annotations

from components.controller import CONTROLLER_PARAMS, Controller, law_params
from components.process_entry import run_component
from wbc.laws.lp_law import LPLaw, LPParams


class LPController(Controller):
    """u = argmin ||J u + eta e||_1 under the constraints of 5.29, one LP per robot/state."""

    law_name = "lp"
    law_type = LPLaw
    gains_type = LPParams
    params = (*law_params(LPParams), *CONTROLLER_PARAMS)


if __name__ == "__main__":
    run_component(LPController)
