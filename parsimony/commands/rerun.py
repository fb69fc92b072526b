"""`parsimony rerun FILE --controller {lp,cascade} -o OUT`: a control law run offline on the
robot states, goals and obstacles of a recording.

OUT holds the recording's inputs, the law's commands and diagnostics on the keys the
controller used, and the recorded ones beside them on ``<key>/recorded``; so
``parsimony report FILE OUT`` compares the two laws on the same inputs. Each state is one step,
dt the difference of state stamps as in the controller process (``components.controller``).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from components.controller import DT_MAX_S, DT_MIN_S, FIRST_DT_S, task_of
from messages.commands import ArmCommand, BaseCommand
from messages.diagnostics import ControllerDiagnostics
from messages.header import Header
from parsimony.output import emit
from parsimony.outputs import writable_output, written_whole
from record.session_file import SessionWriter, read_groups
from wbc.base_motion import unicycle, wheel_speeds
from wbc.cascade_law import CascadeLaw, CascadeParams
from wbc.lp_law import LPLaw, LPParams
from wbc.obstacles import Circle
from wbc.robot import MobileManipulator
from wbc.task import MEASUREMENT_TOLERANCE, same_task

ROBOT = Path(__file__).resolve().parents[2] / "deploy" / "robots" / "little_john.yaml"
LAWS = {"lp": lambda robot: LPLaw(robot, LPParams()),
        "cascade": lambda robot: CascadeLaw(robot, CascadeParams())}  # fmt: skip
OUTPUTS = ("base/command", "arm/command", "control/diagnostics")
"""The topics the law writes; the recorded ones move to ``<key>/recorded``."""
BEFORE_STATE = ("control/goal", "world/obstacles")
"""The estimator publishes these before the state of the same stamp, which they hold for."""


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser("rerun", help="run a law offline on a recording's inputs",
                                   description=__doc__.split("\n\n")[1])  # fmt: skip
    parser.add_argument("file", type=Path, help="MCAP session")
    parser.add_argument("--controller", choices=tuple(LAWS), required=True)
    parser.add_argument("-o", "--output", type=Path, required=True, help="the MCAP to write")
    parser.add_argument("--robot", type=Path, default=ROBOT, help="robot description")
    parser.add_argument("--force", action="store_true", help="replace an existing output")
    return parser


def run(args: argparse.Namespace) -> int:
    problem = writable_output(args.output, [args.file], args.force)
    if problem:
        print(f"rerun: {problem}", file=sys.stderr)
        return 2
    robot = MobileManipulator.from_yaml(args.robot)
    offline = Offline(LAWS[args.controller](robot), args.controller, robot)
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
    recorded commands and diagnostics renamed ``.../recorded``), and each valid state with a
    goal gets one step of the law, written as its commands and diagnostics."""

    def __init__(self, law, name: str, robot: MobileManipulator) -> None:
        self.law, self.name, self.robot = law, name, robot
        self.task, self.obstacles, self.last_ns, self.steps = None, (), None, 0

    def take(self, out: SessionWriter, record) -> None:
        if record.message is None:
            return
        name, key, message = record.topic_name, record.key, record.message
        if name in OUTPUTS:
            out.write(f"{key}/recorded", message, record.log_time_ns)
            return
        out.write(key, message, record.log_time_ns)
        if name == "control/goal":
            new = task_of(message)
            if self.task is None or not same_task(self.task, new, MEASUREMENT_TOLERANCE):
                self.law.reset()
            self.task = new
        elif name == "world/obstacles":
            self.obstacles = tuple(Circle(c.x, c.y, c.radius) for c in message.circles)
        elif name == "robot/state" and message.valid and self.task is not None:
            stamp = message.header.stamp_ns
            dt = FIRST_DT_S if self.last_ns is None else (stamp - self.last_ns) / 1e9
            self.last_ns = stamp
            output = self.law.step(np.array(message.configuration()), self.task,
                                   min(max(dt, DT_MIN_S), DT_MAX_S), self.obstacles)  # fmt: skip
            write_step(out, key[: -len(name) - 1], self.name, stamp, output, message, self.robot)
            self.steps += 1


def write_step(out, namespace: str, law: str, stamp: int, output, state, robot) -> None:
    """The commands and diagnostics of one step, stamped with the state's stamp."""
    u = output.u if output.ok and np.all(np.isfinite(output.u)) else np.zeros(8)
    base = wheel_speeds(*unicycle(u[0], u[1], u[2], state.base_pose[2]), robot.base)
    header = Header(stamp_ns=stamp, frame="world", seq=0, source=f"rerun_{law}")
    out.write(f"{namespace}/base/command", BaseCommand(
        header=header, forward_velocity=base.forward, angular_velocity=base.angular,
        left_wheel=base.left_wheel, right_wheel=base.right_wheel))  # fmt: skip
    out.write(f"{namespace}/arm/command",
              ArmCommand(header=header, joint_velocities=tuple(u[3:].tolist())))  # fmt: skip
    error = output.error_norm if math.isfinite(output.error_norm) else None
    out.write(f"{namespace}/control/diagnostics", ControllerDiagnostics(
        header=header, law=law, status=output.status if output.ok else "error",
        nonzero=output.nonzero, practical_nonzero=output.practical_nonzero,
        solve_time_us=output.solve_time_s * 1e6, error_norm=error))  # fmt: skip
