"""messages.truth: the simulator's truth, its configuration, and a recording older than its
scene fields."""

from __future__ import annotations

from messages import IDENTITY_POSE
from messages.obstacles import Solids
from messages.truth import SimTruth
from tests.messages.message_examples import HEADER


def test_true_configuration_is_base_pose_then_arm_joints() -> None:
    truth = SimTruth(
        header=HEADER,
        base_pose=(1.0, 2.0, 0.3),
        arm_joints=(0.1, -0.2),
        end_effector=IDENTITY_POSE,
        contacts=0,
        in_contact=False,
    )
    assert truth.configuration() == [1.0, 2.0, 0.3, 0.1, -0.2]


def test_a_truth_recorded_before_the_scene_fields_reads_with_none() -> None:
    old = {
        "header": HEADER.model_dump(),
        "base_pose": (0.0, 0.0, 0.0),
        "arm_joints": (0.0,),
        "end_effector": IDENTITY_POSE,
        "contacts": 1,
        "in_contact": True,
    }
    truth = SimTruth.model_validate(old)
    assert (truth.goal, truth.reference_pose, truth.obstacles) == (None, None, ())
    assert truth.solids == Solids()
    assert (truth.arm_penetrations, truth.arm_penetrating) == (0, False)
