"""The simulator follows the profile's ``robot:``: a 7-joint and a 12-joint arm step every joint
as commanded, an omnidirectional base moves sideways with the commanded u_b, a fixed base never
moves; a ``start`` of another robot's size is refused naming the joints. The simulator runs on
an open node (a real Zenoh session on loopback), stepped here."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from components.emulated_robot import EmulatedRobot
from components.params import ParamError
from components.runtime import Node
from components.simulator import Simulator
from messages.commands import ArmCommand, BaseCommand
from messages.header import Header
from profiles.deploy_files import DEPLOY, ROBOTS_DIR
from profiles.profile import load_profile
from wbc.robot import MobileManipulator

STEPS = 50


def profile_of(tmp_path: Path, robot: str, start: str = "[0.5, 0.2, 0.0]") -> Path:
    """sim.yaml with ``robot`` as its robot and the base at ``start``."""
    path = tmp_path / f"{robot}.yaml"
    path.write_text(
        f"extends: {DEPLOY / 'sim.yaml'}\n"
        f"robot: {ROBOTS_DIR / robot}.yaml\n"
        "components:\n"
        "  - name: simulator\n"
        f"    params: {{start: {start}, real_time_factor: 0.0, paused: true}}\n"
    )
    return path


def middle(robot: str) -> str:
    """A start of ``robot`` with every joint in the middle of its range."""
    model = MobileManipulator.from_yaml(ROBOTS_DIR / f"{robot}.yaml")
    return str([0.5, 0.2, 0.0, *(0.5 * (model.q_min[3:] + model.q_max[3:])).tolist()])


def drive(
    tmp_path: Path, robot: str, forward: float, lateral: float, joint_speed: float
) -> tuple[np.ndarray, np.ndarray, Simulator]:
    """The robot's q before and after ``STEPS`` steps of the commands given (the wheels at
    ``forward`` each for a differential base), from the middle of its joints' ranges."""
    profile = load_profile(profile_of(tmp_path, robot, middle(robot)))
    with Node(profile, "simulator", Simulator.params) as node:
        sim = Simulator(node)
        try:
            before = sim.world.q.copy()
            names = sim.robot.joint_names
            for _ in range(STEPS):
                header = Header(stamp_ns=sim.now_ns, frame="base", seq=0, source="test")
                base = BaseCommand(
                    header=header,
                    forward_velocity=forward,
                    angular_velocity=0.0,
                    left_wheel=forward if sim.robot.base.kind == "differential" else 0.0,
                    right_wheel=forward if sim.robot.base.kind == "differential" else 0.0,
                    lateral_velocity=lateral,
                )
                arm = ArmCommand(
                    header=header,
                    joint_velocities=(joint_speed,) * len(names),
                    joint_names=names,
                )
                sim._take_command("base/command", base)
                sim._take_command("arm/command", arm)
                sim.step()
            return before, sim.world.q.copy(), sim
        finally:
            sim.shutdown()


@pytest.mark.parametrize("robot", ["arm7_differential", "snake12"])
def test_every_joint_of_a_long_arm_moves(tmp_path: Path, robot: str) -> None:
    before, after, sim = drive(tmp_path, robot, 0.1, 0.0, 0.05)
    assert after.shape == (3 + sim.robot.arm_dof,)
    assert after[0] > before[0]  # the wheels drove it
    np.testing.assert_allclose(after[3:] - before[3:], 0.05 * STEPS * sim.step_ns / 1e9)
    assert sim.node.counters["refused_arm_commands"] == 0


def test_an_omnidirectional_base_moves_sideways(tmp_path: Path) -> None:
    before, after, sim = drive(tmp_path, "youbot", 0.0, 0.2, 0.0)
    seconds = STEPS * sim.step_ns / 1e9
    assert after[1] - before[1] == pytest.approx(0.2 * seconds, rel=0.05)  # heading 0: +y
    assert after[0] == pytest.approx(before[0], abs=1e-6)
    assert after[2] == pytest.approx(before[2], abs=1e-9)


def test_a_fixed_base_never_moves(tmp_path: Path) -> None:
    before, after, _ = drive(tmp_path, "ur5e_fixed", 0.3, 0.3, 0.1)
    np.testing.assert_array_equal(after[:3], before[:3])
    assert np.all(after[3:] > before[3:])


def test_a_start_of_another_robots_size_is_refused(tmp_path: Path) -> None:
    profile = load_profile(profile_of(tmp_path, "arm7_differential", "[0, 0, 0, 0.1, 0.2]"))
    with Node(profile, "simulator", Simulator.params) as node:
        with pytest.raises(ParamError, match=r"start: expected 10 values \(x, y, phi, q1, "):
            Simulator(node)


def test_the_emulated_create_refuses_a_base_that_is_not_differential(tmp_path: Path) -> None:
    path = tmp_path / "emulated_youbot.yaml"
    path.write_text(f"extends: {DEPLOY / 'emulated.yaml'}\nrobot: {ROBOTS_DIR / 'youbot'}.yaml\n")
    with Node(load_profile(path), "simulator", EmulatedRobot.params) as node:
        with pytest.raises(ParamError, match="drives a differential base, not the omnidirectional"):
            EmulatedRobot(node)
