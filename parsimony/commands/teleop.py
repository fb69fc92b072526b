"""`parsimony teleop`: drive the robot from the keyboard, under the robot's velocity and joint
limits (the controller applies them: ``components.control_step.teleop_step``).

Keys: ``w``/``s`` forward and back, ``a``/``d`` turn left and right, ``1``..``9`` choose a
joint, ``i``/``k`` move it up and down, space: everything still, ``q`` (or Ctrl-C): quit. A key
holds its motion ``HOLD_S`` (longer than a keyboard's repeat delay), then the motion stops; the
command goes out at ``--rate`` while the tool runs, and the controller commands zero when it
stops coming (its dead-man timeout). While teleoperated the controller and the supervisor
yield their goal, until a new goal. Only a user who may command the robot may teleoperate.
"""

from __future__ import annotations

import argparse
import math
import os
import select
import sys
import termios
import time
import tty
from dataclasses import dataclass, replace

from components.stop_latch import release_refusal
from launch.query import QueryError
from messages import codec, topics
from messages.header import Header
from messages.teleop import TeleopCommand
from parsimony.target_options import (
    EXIT_BAD_INPUT,
    EXIT_REFUSED,
    fail,
    profile_and_target,
    target_options,
)
from profiles.access import tool_user
from profiles.profile import ProfileError
from view.station_teleop import PANEL_FORWARD_M_S, PANEL_TURN_RAD_S
from wbc.robot import MobileManipulator

HOLD_S = 0.6
"""How long a key press holds its motion."""
KEYS = "w/s forward/back, a/d turn, 1-9 joint, i/k joint up/down, space still, q quit"


@dataclass(frozen=True)
class Hand:
    """What the keys ask now: base speeds, the chosen joint and its velocity."""

    forward: float = 0.0
    turn: float = 0.0
    joint: int = 0
    joint_velocity: float = 0.0


def press(key: str, hand: Hand, speeds: tuple[float, float, float], joints: int) -> Hand | None:
    """``hand`` after ``key`` (None: quit); ``speeds`` are (forward, turn, joint)."""
    forward, turn, joint = speeds
    moves = {
        "w": {"forward": forward},
        "s": {"forward": -forward},
        "a": {"turn": turn},
        "d": {"turn": -turn},
        "i": {"joint_velocity": joint},
        "k": {"joint_velocity": -joint},
    }
    if key in ("q", "\x03"):
        return None
    if key == " ":
        return replace(Hand(), joint=hand.joint)
    if key.isdigit() and 1 <= int(key) <= joints:
        return Hand(joint=int(key) - 1)
    return replace(hand, **moves[key]) if key in moves else hand


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare `teleop` and its arguments."""
    parser = subparsers.add_parser(
        "teleop",
        parents=[target_options()],
        help="drive the robot from the keyboard",
        description=__doc__.split("\n\n")[0] + " Keys: " + KEYS + ".",
    )
    parser.add_argument("--speed", type=float, default=PANEL_FORWARD_M_S, help="forward speed, m/s")
    parser.add_argument("--turn", type=float, default=PANEL_TURN_RAD_S, help="turn rate, rad/s")
    parser.add_argument("--joint-speed", type=float, default=0.3, help="joint speed, rad/s")
    parser.add_argument("--rate", type=float, default=20.0, help="commands a second")
    return parser


def run(args: argparse.Namespace) -> int:
    for option in ("speed", "turn", "joint_speed", "rate"):
        value = getattr(args, option)
        if not (math.isfinite(value) and value > 0.0):
            flag = "--" + option.replace("_", "-")
            print(f"{flag}: expected a finite number > 0, got {value}", file=sys.stderr)
            return EXIT_BAD_INPUT
    try:
        profile, target = profile_and_target(args)
        if profile.robot is None:
            raise ProfileError(f"{args.profile}: no robot to teleoperate")
        names = MobileManipulator.from_yaml(profile.robot).joint_names
        refusal = release_refusal(profile, tool_user(), "teleoperate the robot")
        if refusal is not None:
            print(refusal, file=sys.stderr)
            return EXIT_REFUSED
        if not sys.stdin.isatty():
            print("teleop reads its keys from a terminal: run it in one", file=sys.stderr)
            return EXIT_BAD_INPUT
        with target.open() as session:
            publisher = session.declare_publisher(topics.TELEOP_COMMAND.key(profile.namespace))
            drive(args, names, lambda command: publisher.put(codec.encode(command)))
    except (ProfileError, QueryError) as error:
        return fail(error)
    return 0


def drive(args: argparse.Namespace, names: tuple[str, ...], put) -> None:
    """Read keys until ``q``, putting the command at ``args.rate``; zero on the way out. The
    keys are read from the descriptor as they come (a buffered read would keep the second of
    two keys typed at once until a third)."""
    speeds = (args.speed, args.turn, args.joint_speed)
    hand, pressed = Hand(), 0.0
    terminal = sys.stdin.fileno()
    saved = termios.tcgetattr(terminal)
    print(f"teleop: {KEYS}", file=sys.stderr)
    try:
        tty.setcbreak(terminal)
        while True:
            if select.select([terminal], [], [], 1.0 / args.rate)[0]:
                for key in os.read(terminal, 64).decode(errors="replace"):
                    after = press(key, hand, speeds, len(names))
                    if after is None:
                        return
                    hand, pressed = after, time.monotonic()
            if time.monotonic() - pressed > HOLD_S:
                hand = replace(Hand(), joint=hand.joint)
            put(command_of(hand, names))
    finally:
        put(command_of(replace(Hand(), joint=hand.joint), names))
        termios.tcsetattr(terminal, termios.TCSADRAIN, saved)


def command_of(hand: Hand, names: tuple[str, ...]) -> TeleopCommand:
    """The message of ``hand``."""
    header = Header(stamp_ns=time.time_ns(), frame="base", seq=0, source=tool_user())
    return TeleopCommand(
        header=header,
        forward=hand.forward,
        turn=hand.turn,
        joint=names[hand.joint] if names else "",
        joint_velocity=hand.joint_velocity,
    )
