"""`parsimony export SESSION.mcap --ros2 -o DIR`: a recorded session as a ROS 2 Jazzy bag
(ros2.bag): /joint_states, /tf and /odom from the robot's recorded states, which
``ros2 bag info`` and ``ros2 bag play`` read; its size and time span printed."""

from __future__ import annotations

import argparse
import shutil
import sys
from collections.abc import Iterator
from pathlib import Path

from rosbags.rosbag2 import WriterError

from messages.state import RobotState
from messages.topics import ROBOT_STATE
from outputs.stdout import emit, json_text
from parsimony.commands.robot_option import robot_file
from profiles.deploy_files import ROBOT_FILE
from record.session_reader import read_session
from ros2.bag import write_bag
from wbc.robot import MobileManipulator, RobotDescriptionError


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "export",
        help="a recording as a ROS 2 bag (--ros2)",
        description="Write the robot's recorded states as a ROS 2 Jazzy bag (MCAP storage, "
        "ros2msg schemas, metadata.yaml): /joint_states, /tf and /odom, one message per state.",
    )
    parser.add_argument("file", type=Path, metavar="SESSION", help="MCAP session")
    parser.add_argument("--ros2", action="store_true", required=True, help="a ROS 2 bag")
    parser.add_argument("-o", "--out", type=Path, required=True, help="the bag's directory (new)")
    parser.add_argument(
        "--robot",
        type=robot_file,
        default=ROBOT_FILE,
        metavar="NAME|PATH",
        help="the recorded robot's description: a zoo name or a file",
    )
    parser.add_argument("--json", action="store_true", help="print the result as JSON")
    return parser


def states(path: Path) -> Iterator[RobotState]:
    """The robot's states recorded in ``path``, in log-time order."""
    for recorded in read_session(path, {ROBOT_STATE.name}):
        if isinstance(recorded.message, RobotState):
            yield recorded.message


def run(args: argparse.Namespace) -> int:
    if args.out.exists():
        print(f"export: {args.out} exists: give a new directory", file=sys.stderr)
        return 2
    try:
        robot = MobileManipulator.from_yaml(args.robot)
        if not args.file.is_file():
            raise FileNotFoundError(f"no such file: {args.file}")
        print(f"export: {args.file} -> {args.out} (ROS 2 jazzy, mcap)", file=sys.stderr)
        result = write_bag(args.out, robot, states(args.file))
    except (OSError, ValueError, WriterError, RobotDescriptionError) as error:
        if args.out.is_dir():
            shutil.rmtree(args.out)  # made by this run alone: it did not exist before
        print(f"export: {error}", file=sys.stderr)
        return 2
    if result["start_ns"] is None:
        print(f"export: {args.file} holds no valid robot state: the bag is empty", file=sys.stderr)
    if result["invalid_states_left_out"]:
        left = result["invalid_states_left_out"]
        print(f"export: {left} states without a fix (valid false) left out", file=sys.stderr)
    if args.json:
        emit(json_text(result, indent=2))
    else:
        messages = sum(result["topics"].values())
        emit(
            f"{result['bag']}: {messages} messages on {len(result['topics'])} topics, "
            f"{result['size_bytes']} bytes, {result['duration_s']:.3f} s "
            f"from {result['start_ns']} to {result['end_ns']} ns"
        )
    return 0
