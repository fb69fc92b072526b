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
from parsimony.outputs import writable_output
from record.session_file import SessionWriter, read_session
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
    law = LAWS[args.controller](robot)
    task, obstacles, last_ns, steps = None, (), None, 0
    try:
        records = sorted(read_session(args.file), key=lambda r: (
            r.log_time_ns, r.topic_name not in BEFORE_STATE))  # fmt: skip
    except OSError as error:
        print(f"rerun: {error}", file=sys.stderr)
        return 2
    with SessionWriter(args.output) as out:
        for record in records:
            if record.message is None:
                continue
            name, key, message = record.topic_name, record.key, record.message
            if name in OUTPUTS:
                out.write(f"{key}/recorded", message, record.log_time_ns)
                continue
            out.write(key, message, record.log_time_ns)
            namespace = key[: -len(name) - 1]
            if name == "control/goal":
                new = task_of(message)
                if task is None or not same_task(task, new, MEASUREMENT_TOLERANCE):
                    law.reset()
                task = new
            elif name == "world/obstacles":
                obstacles = tuple(Circle(c.x, c.y, c.radius) for c in message.circles)
            elif name == "robot/state" and message.valid and task is not None:
                stamp = message.header.stamp_ns
                dt = FIRST_DT_S if last_ns is None else (stamp - last_ns) / 1e9
                last_ns = stamp
                output = law.step(np.array(message.configuration()), task,
                                  min(max(dt, DT_MIN_S), DT_MAX_S), obstacles)  # fmt: skip
                write_step(out, namespace, args.controller, stamp, output, message, robot)
                steps += 1
    emit(f"{steps} steps of the {args.controller} law written to {args.output}")
    return 0


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
