"""The classic cascade controller as a process: appendix B (``wbc.cascade_law``).

Run as ``python -m components.cascade_controller --profile P --name N``; everything but
the law and its parameters is the controller shell of ``components.controller``. A goal's
``beta`` does not apply to this law.
"""

from __future__ import annotations

from components.controller import CONTROLLER_PARAMS, Controller
from components.params import Param
from components.runtime import run_component
from wbc.cascade_law import CascadeLaw, CascadeParams


class CascadeController(Controller):
    """A pseudoinverse outer loop and a linearising inner loop for the base, per robot/state."""

    law_name = "cascade"
    law_type = CascadeLaw
    gains_type = CascadeParams
    params = (
        Param("eta", float, CascadeParams.eta, low=1e-3, high=100.0, doc="task gain, 1/s"),
        Param("offset", float, CascadeParams.offset, low=0.01, high=1.0, doc="d, m"),
        Param("k1", float, CascadeParams.k1, low=1e-3, high=100.0, doc="inner gain on x1, 1/s"),
        Param("k2", float, CascadeParams.k2, low=1e-3, high=100.0, doc="inner gain on y1, 1/s"),
        Param("max_lead", float, CascadeParams.max_lead, low=0.01, high=10.0,
              doc="how far the reference point may lead the base, m"),  # fmt: skip
        *CONTROLLER_PARAMS,
    )


if __name__ == "__main__":
    run_component(CascadeController)
