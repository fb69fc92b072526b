"""`parsimony export SESSION.mcap --ros2 -o DIR`: a recorded session as a ROS 2 Jazzy bag
(ros2.bag) of the live bridge's topics: /joint_states, /tf, /odom and /robot_description from
the robot's recorded states, /camera/image/compressed and /camera/camera_info from its JPEG
camera frames, /diagnostics from its controller diagnostics and supervisor statuses; which
``ros2 bag info`` and ``ros2 bag play`` read; its size and time span printed.
`parsimony export --urdf -o FILE`: the robot's URDF (ros2.urdf), for rviz2's RobotModel."""

from __future__ import annotations

import argparse
import shutil
import sys
from collections.abc import Iterator
from pathlib import Path

from pydantic import BaseModel
from rosbags.rosbag2 import WriterError

from messages.topics import CAMERA_IMAGE, CONTROL_DIAGNOSTICS, ROBOT_STATE, SUPERVISOR_STATUS
from outputs.stdout import emit, json_text
from parsimony.commands.robot_option import add_robot_option
from record.session_reader import read_session
from ros2.bag import write_bag
from ros2.urdf import urdf
from wbc.robot import MobileManipulator, RobotDescriptionError


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "export",
        help="a recording as a ROS 2 bag (--ros2), the robot's URDF (--urdf)",
        description="Write a recording as a ROS 2 Jazzy bag (MCAP storage, ros2msg schemas, "
        "metadata.yaml) of the live bridge's topics: /joint_states, /tf and /odom, one message "
        "per robot state; /robot_description (the URDF, latched); /camera/image/compressed and "
        "/camera/camera_info per JPEG camera frame; /diagnostics per controller diagnostics or "
        "supervisor status. Or the robot's URDF, whose frames the bag's /tf names.",
    )
    parser.add_argument("file", type=Path, nargs="?", metavar="SESSION", help="MCAP session")
    kind = parser.add_mutually_exclusive_group(required=True)
    kind.add_argument("--ros2", action="store_true", help="a ROS 2 bag of SESSION")
    kind.add_argument("--urdf", action="store_true", help="the robot's URDF")
    parser.add_argument(
        "-o", "--out", type=Path, required=True, help="the bag's directory or the URDF's file (new)"
    )
    add_robot_option(parser, "the recorded robot's description: a zoo name or a file")
    parser.add_argument("--json", action="store_true", help="print the result as JSON")
    return parser


BAG_TOPICS = (ROBOT_STATE, CAMERA_IMAGE, CONTROL_DIAGNOSTICS, SUPERVISOR_STATUS)
"""The recorded topics a bag is made from (``ros2.bag``)."""


def recorded(path: Path) -> Iterator[BaseModel]:
    """The messages of ``BAG_TOPICS`` recorded in ``path``, in log-time order (one pass)."""
    for found in read_session(path, {topic.name for topic in BAG_TOPICS}):
        if found.message is not None:
            yield found.message


def run(args: argparse.Namespace) -> int:
    if args.out.exists():
        print(f"export: {args.out} exists: give a new path", file=sys.stderr)
        return 2
    if (args.file is None) == bool(args.ros2):
        wanted = "--ros2 exports a SESSION" if args.ros2 else "--urdf takes no SESSION"
        print(f"export: {wanted}", file=sys.stderr)
        return 2
    return export_bag(args) if args.ros2 else export_urdf(args)


def export_urdf(args: argparse.Namespace) -> int:
    try:
        text = urdf(MobileManipulator.from_yaml(args.robot))
        args.out.write_text(text)
    except (OSError, RobotDescriptionError) as error:
        print(f"export: {error}", file=sys.stderr)
        return 2
    result = {"urdf": str(args.out), "size_bytes": len(text.encode())}
    emit(json_text(result, indent=2) if args.json else f"{args.out}: {result['size_bytes']} bytes")
    return 0


def export_bag(args: argparse.Namespace) -> int:
    try:
        robot = MobileManipulator.from_yaml(args.robot)
        if not args.file.is_file():
            raise FileNotFoundError(f"no such file: {args.file}")
        print(f"export: {args.file} -> {args.out} (ROS 2 jazzy, mcap)", file=sys.stderr)
        result = write_bag(args.out, robot, recorded(args.file))
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
    if result["frames_not_jpeg_left_out"]:
        left = result["frames_not_jpeg_left_out"]
        print(f"export: {left} camera frames not JPEG left out", file=sys.stderr)
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
