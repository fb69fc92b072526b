"""The simulator's ground truth is for tests and reports: the runtime refuses it to every
estimator and controller, so they see the world only through the sensors."""

from __future__ import annotations

from messages import topics
from profiles.deploy_files import DEPLOY


def test_no_estimator_or_controller_may_read_the_ground_truth(deployed) -> None:
    from components.lp_controller import LPController
    from components.runtime import Node
    from components.simulator import Simulator
    from components.state_estimator import StateEstimator

    system = deployed(DEPLOY / "sim.yaml")
    for name, component in (("state_estimator", StateEstimator), ("controller", LPController)):
        with Node(system.profile, name, component.params) as node:
            try:
                node.subscribe(topics.SIM_TRUTH)
            except ValueError as error:
                assert "may not read the ground truth" in str(error)
            else:
                raise AssertionError(f"{name} subscribed to sim/truth")
    with Node(system.profile, "simulator", Simulator.params) as node:  # a driver may
        node.subscribe(topics.SIM_TRUTH)
