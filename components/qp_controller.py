"""The QP controller as a process: the same rows and terms as the LP as a quadratic program
(``wbc.laws.qp_law``), for the comparison of chapter 7's future work 5.

Run as ``python -m components.qp_controller --profile P --name N``; everything but the law is
the controller shell of ``components.controller``. Every gain of ``QPParams`` is a run-time
parameter with the bounds its term declares.
"""

from __future__ import annotations

from components.controller import CONTROLLER_PARAMS, Controller, law_params
from components.process_entry import run_component
from wbc.laws.qp_law import QPLaw, QPParams


class QPController(Controller):
    """u = argmin ||J u + eta e||^2 + lambda ||u||^2 under the rows of 5.29, one QP per state."""

    law_name = "qp"
    law_type = QPLaw
    gains_type = QPParams
    params = (*law_params(QPParams), *CONTROLLER_PARAMS)


if __name__ == "__main__":
    run_component(QPController)
