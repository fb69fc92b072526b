"""`parsimony rerun FILE --controller {lp,cascade} -o OUT`: a control law run offline on the
robot states, goals and obstacles of a recording.

OUT holds the recording's inputs, the law's commands and diagnostics on the keys the
controller used, and the recorded ones beside them on ``<key>/recorded``; so
``parsimony report FILE OUT`` compares the two laws on the same inputs. Each state is one step
of the controller process's own (``components.control_step``), at the state's stamp (a
recording does not say how late a state came, so none is stale); the recorded law is run with
the gains its diagnostics carry at each step, another law with its defaults. On a lockstep
recording of the same law, the commands come out bit for bit as recorded.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from analysis.judge import RERUN_SOURCE
from components.cascade_controller import CascadeController
from components.control_step import ControlStep, Step, gains_of
from components.controller import Controller, diagnostics_of
from components.lp_controller import LPController
from components.qp_controller import QPController
from messages import topics
from messages.commands import ArmCommand, BaseCommand
from messages.header import Header
from messages.obstacles import obstacles_of
from outputs.files import writable_output, written_whole
from outputs.stdout import emit
from parsimony.commands.robot_option import add_robot_option
from record.session_file import Recorded, SessionWriter
from record.session_reader import read_groups
from wbc.robot import MobileManipulator, RobotDescriptionError

LAWS: dict[str, type[Controller]] = {
    c.law_name: c for c in (LPController, CascadeController, QPController)
}
"""The controllers whose law can be run again, by law name."""
OUTPUTS = tuple(
    t.name for t in (topics.BASE_COMMAND, topics.ARM_COMMAND, topics.CONTROL_DIAGNOSTICS)
)
"""The topics the law writes; the recorded ones move to ``<key>/recorded``."""
BEFORE_STATE = tuple(
    t.name for t in (topics.CONTROL_GOAL, topics.WORLD_OBSTACLES, topics.CONTROL_DIAGNOSTICS)
)
"""Taken before the state of the same stamp: the estimator publishes the goal and obstacles
a state holds for before it, and the diagnostics answering it carry the gains it ran with."""


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "rerun",
        help="run a law offline on a recording's inputs",
        description=__doc__.split("\n\n")[1],
    )
    parser.add_argument("file", type=Path, help="MCAP session")
    parser.add_argument("--controller", choices=tuple(LAWS), required=True)
    parser.add_argument("-o", "--output", type=Path, required=True, help="the MCAP to write")
    add_robot_option(parser)
    parser.add_argument("--force", action="store_true", help="replace an existing output")
    return parser


def run(args: argparse.Namespace) -> int:
    problem = writable_output(args.output, [args.file], args.force)
    if problem:
        print(f"rerun: {problem}", file=sys.stderr)
        return 2
    try:
        offline = Offline(LAWS[args.controller], MobileManipulator.from_yaml(args.robot))
    except (OSError, RobotDescriptionError) as error:
        print(f"rerun: {error}", file=sys.stderr)
        return 2
    try:
        with written_whole(args.output) as partial, SessionWriter(partial) as out:
            for group in read_groups(args.file):  # streamed: memory does not grow with it
                for record in sorted(group, key=lambda r: r.topic_name not in BEFORE_STATE):
                    offline.take(out, record)
    except OSError as error:
        print(f"rerun: {error}", file=sys.stderr)
        return 2
    emit(f"{offline.steps} steps of the {args.controller} law written to {args.output}")
    return 0


class Offline:
    """The law run on a recording's messages one by one: each is copied to the output (the
    recorded commands and diagnostics renamed ``.../recorded``), and each state is one
    ``ControlStep``, written as its commands and diagnostics."""

    def __init__(self, controller: type[Controller], robot: MobileManipulator) -> None:
        self.name, self.gains_type = controller.law_name, controller.gains_type
        self.stepper = ControlStep(self.name, controller.law_type, robot, self.gains_type())
        self.steps = 0
        self.recorded_gains = False  # whether the recording said the gains of this law

    def take(self, out: SessionWriter, record: Recorded) -> None:
        if record.message is None:
            return
        name, key, message = record.topic_name, record.key, record.message
        if name in OUTPUTS:
            out.write(f"{key}/recorded", message, record.log_time_ns)
            if name == topics.CONTROL_DIAGNOSTICS.name and message.law == self.name:
                self.stepper.set_gains(gains_of(self.gains_type, message.parameters, None))
                self.recorded_gains = True
            return
        out.write(key, message, record.log_time_ns)
        if name == topics.CONTROL_GOAL.name:
            try:
                self.stepper.take_goal(message)  # a goal the law refuses: no goal, as live
            except ValueError:
                return
            if not self.recorded_gains:  # the defaults, the goal's eta and beta over them
                self.stepper.set_gains(gains_of(self.gains_type, {}, message))
        elif name == topics.WORLD_OBSTACLES.name:
            self.stepper.take_obstacles(obstacles_of(message))
        elif name == topics.ROBOT_STATE.name:
            stamp = message.header.stamp_ns
            step = self.stepper.step(message, stamp, math.inf)
            names = self.stepper.robot.joint_names
            write_step(out, key[: -len(name) - 1], self.name, step, self.stepper.gains, names)
            self.steps += 1


def write_step(
    out: SessionWriter, namespace: str, law: str, step: Step, gains, joint_names: tuple[str, ...]
) -> None:
    """The commands and diagnostics of one step, stamped with its state's stamp, the arm's
    joints named ``joint_names`` (the robot's description's)."""
    header = Header(stamp_ns=step.stamp_ns, frame="world", seq=0, source=f"{RERUN_SOURCE}{law}")
    forward, angular, left, right = step.wheels
    out.write(
        f"{namespace}/base/command",
        BaseCommand(
            header=header,
            forward_velocity=forward,
            angular_velocity=angular,
            left_wheel=left,
            right_wheel=right,
            lateral_velocity=step.lateral,
        ),
    )
    arm = ArmCommand(header=header, joint_velocities=step.joints, joint_names=joint_names)
    out.write(f"{namespace}/arm/command", arm)
    out.write(f"{namespace}/control/diagnostics", diagnostics_of(step, law, gains, header))
