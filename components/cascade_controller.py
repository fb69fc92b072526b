"""The classic cascade controller as a process: appendix B (``wbc.laws.cascade_law``).

Run as ``python -m components.cascade_controller --profile P --name N``; everything but
the law is the controller shell of ``components.controller``. A goal's
``beta`` does not apply to this law.
"""

from __future__ import annotations

from components.controller import CONTROLLER_PARAMS, Controller, law_params
from components.process_entry import run_component
from wbc.laws.cascade_law import CascadeLaw, CascadeParams


class CascadeController(Controller):
    """A pseudoinverse outer loop and a linearising inner loop for the base, per robot/state."""

    law_name = "cascade"
    law_type = CascadeLaw
    gains_type = CascadeParams
    params = (*law_params(CascadeParams), *CONTROLLER_PARAMS)


if __name__ == "__main__":
    run_component(CascadeController)
