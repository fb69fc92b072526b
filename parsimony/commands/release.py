"""`parsimony release`: release the latched emergency stop of `parsimony stop`; only a user
who may command the robot may (``components.stop_latch.release_refusal``)."""

from __future__ import annotations

import argparse

from parsimony.commands.stop import add_giver, give


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare `release` and its arguments."""
    return add_giver(
        subparsers,
        "release",
        "release the stop of `parsimony stop`: the robot may move again",
        "Clear the namespace's stopped state: the drivers take commands again and the "
        "controller and the supervisor go on with the goal they hold. Only a user who may "
        "command the robot (a writer of control/goal and goal/request under zenoh.access) may.",
    )


def run(args: argparse.Namespace) -> int:
    return give(args, stopped=False)
