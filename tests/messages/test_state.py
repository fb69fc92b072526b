"""messages.state: the robot state's whole-body configuration."""

from __future__ import annotations

from tests.messages.message_examples import STATE


def test_configuration_is_base_pose_then_arm_joints() -> None:
    assert STATE.configuration() == [1.0, 2.0, 0.3, 0.1, -0.2, 0.3, -0.4, 0.5]
