"""For the tests of analysis: real kinematic runs of the LP and the cascade law
(``runs``), and the messages a controller and a state estimator would have published over
them (``session_of``), as the judge and the report read them."""

from __future__ import annotations

from pathlib import Path

import pytest

from messages import topics
from messages.commands import ArmCommand, BaseCommand
from messages.diagnostics import ControllerDiagnostics
from messages.goal import Goal
from messages.header import Header
from messages.topics import (
    ARM_COMMAND,
    BASE_COMMAND,
    CONTROL_DIAGNOSTICS,
    CONTROL_GOAL,
    GOAL_REQUEST,
    ROBOT_STATE,
)
from profiles.deploy_files import ROBOT_FILE
from record.session_file import SessionWriter
from tests.robot_states import state_at
from wbc.base_motion import unicycle, wheel_speeds
from wbc.geometry import scenarios
from wbc.laws.cascade_law import CascadeLaw
from wbc.laws.kinematic_run import Run, integrate
from wbc.laws.lp_law import LPLaw, LPParams
from wbc.robot import MobileManipulator
from wbc.task import PoseTask

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
DT = scenarios.DT
DT_NS = round(DT * 1e9)
START_NS = 1_000_000_000
FIGURES = (
    "control_inputs.png",
    "nonzero_entries.png",
    "error.png",
    "joints.png",
    "end_effector_path.png",
    "base_path.png",
)


def header(stamp_ns: int, frame: str, seq: int) -> Header:
    return Header(stamp_ns=stamp_ns, frame=frame, seq=seq, source="test")


def session_of(run: Run, law: str, task: PoseTask) -> dict[str, list]:
    """The messages a controller and a state estimator would publish over ``run``: each step's
    state, and the commands and diagnostics answering it with the state's stamp."""
    session: dict[str, list] = {
        CONTROL_GOAL.name: [
            Goal(header=header(START_NS, "world", 0), task="pose", pose=tuple(task.pose))
        ]
    }
    for topic in (ROBOT_STATE, BASE_COMMAND, ARM_COMMAND, CONTROL_DIAGNOSTICS):
        session[topic.name] = []
    for seq, (q, out) in enumerate(zip(run.configurations, run.outputs, strict=True)):
        stamp = START_NS + seq * DT_NS
        base = wheel_speeds(*unicycle(out.u[0], out.u[1], out.u[2], q[2]), ROBOT.base)
        session[ROBOT_STATE.name].append(state_at(ROBOT, q, header(stamp, "world", seq)))
        session[BASE_COMMAND.name].append(
            BaseCommand(
                header=header(stamp, "base", seq),
                forward_velocity=base.forward,
                angular_velocity=base.angular,
                left_wheel=base.left_wheel,
                right_wheel=base.right_wheel,
            )
        )
        session[ARM_COMMAND.name].append(
            ArmCommand(header=header(stamp, "arm", seq), joint_velocities=tuple(out.u[3:]))
        )
        session[CONTROL_DIAGNOSTICS.name].append(
            ControllerDiagnostics(
                header=header(stamp, "world", seq),
                law=law,
                status=out.status,
                nonzero=out.nonzero,
                practical_nonzero=out.practical_nonzero,
                solve_time_us=out.solve_time_s * 1e6,
                error_norm=out.error_norm,
            )
        )
    return session


@pytest.fixture(scope="module")
def runs() -> dict[str, tuple[Run, dict[str, list]]]:
    task = PoseTask(ROBOT.fkm(scenarios.REACH_GOAL))
    laws = {"LP": LPLaw(ROBOT, LPParams()), "cascade": CascadeLaw(ROBOT)}
    result = {}
    for label, law in laws.items():
        run = integrate(law, scenarios.HOME, task, DT, 1500)
        assert run.converged
        result[label] = (run, session_of(run, label, task))
    return result


def write(
    path: Path, session: dict[str, list], poison: Goal | None = None, namespace: str = "far"
) -> Path:
    """``session`` as a recorder of ``namespace`` writes it, in stamp order, ``poison`` on
    goal/request half way through (when it came)."""
    recorded = sorted(
        (m.header.stamp_ns, topic, m) for topic, found in session.items() for m in found
    )
    with SessionWriter(path) as writer:
        for index, (_, topic, message) in enumerate(recorded):
            if poison is not None and index == len(recorded) // 2:
                writer.write(GOAL_REQUEST.key(namespace), poison)
            writer.write(topics.TOPICS[topic].key(namespace), message)
    return path
