"""`parsimony layout PROFILE [-o FILE]`: the Foxglove layout of the profile's namespace
(view.foxglove_layout): the 3-D panel on the robot, the annotated camera image, plots of the
task error, of the nonzero entries of u and of the arm's joints (each by the name the profile's
robot description gives it), the controller's diagnostics, the supervisor's status, a
Parameters panel and a Teleop panel on ``teleop/command``. Foxglove imports it from the file
(Layouts, Import from file); without ``-o`` it is printed."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from outputs.stdout import emit
from profiles.profile import Profile, ProfileError, load_profile
from view.foxglove_layout import layout
from wbc.robot import MobileManipulator, RobotDescriptionError


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "layout", help="the Foxglove layout of a profile's view", description=__doc__
    )
    parser.add_argument("profile", type=Path, help="deploy profile of the system")
    parser.add_argument("-o", "--output", type=Path, help="write it to this file")
    parser.add_argument("--force", action="store_true", help="write over an existing file")
    return parser


def joint_names(profile: Profile) -> tuple[str, ...]:
    """The arm joints' names of the profile's robot description (none without one)."""
    return MobileManipulator.from_yaml(profile.robot).joint_names if profile.robot else ()


def write_layout(namespace: str, path: Path, force: bool, joints: Sequence[str] = ()) -> None:
    """The layout of ``namespace`` (its joints' plot on ``joints``) into ``path``;
    ``FileExistsError`` if there is a file there and not ``force``."""
    if path.exists() and not force:
        raise FileExistsError(f"{path} exists (--force writes over it)")
    path.write_text(layout(namespace, joints).to_json() + "\n")


def run(args: argparse.Namespace) -> int:
    try:
        profile = load_profile(args.profile)
        namespace, joints = profile.namespace, joint_names(profile)
        if args.output is None:
            emit(layout(namespace, joints).to_json())
        else:
            write_layout(namespace, args.output, args.force, joints)
            print(
                f"layout: {args.output}: import it in Foxglove (Layouts, Import from file)",
                file=sys.stderr,
            )
    except (ProfileError, RobotDescriptionError, OSError) as error:
        print(f"layout: {error}", file=sys.stderr)
        return 2
    return 0
