"""The options every command that talks to a running system shares: the profile, a timeout."""

from __future__ import annotations

import argparse
import os
import sys

from launch.query import DEFAULT_TIMEOUT_S, NoRouter, QueryError, Target
from profiles.profile import Profile, ProfileError, load_profile

PROFILE_ENV = "PARSIMONY_PROFILE"
"""The profile used when `--profile` is not given."""


def target_options() -> argparse.ArgumentParser:
    """A parent parser with ``--profile``, ``--timeout`` and ``--json``."""
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument(
        "--profile",
        default=os.environ.get(PROFILE_ENV),
        help=f"the deploy profile of the running system (default: ${PROFILE_ENV})",
    )
    common.add_argument(
        "--timeout",
        type=float,
        default=DEFAULT_TIMEOUT_S,
        metavar="S",
        help=f"seconds to wait for the running system's answers (default {DEFAULT_TIMEOUT_S:g})",
    )
    common.add_argument("--json", action="store_true", help="print JSON")
    return common


def profile_and_target(args: argparse.Namespace) -> tuple[Profile, Target]:
    """The profile named by the options and how to reach its system (``ProfileError``)."""
    if args.profile is None:
        raise ProfileError(f"no profile: pass --profile or set {PROFILE_ENV}")
    profile = load_profile(args.profile)
    return profile, Target(profile.namespace, profile.zenoh)


EXIT_REFUSED = 1
"""The running system did not answer, or refused what was asked."""
EXIT_BAD_INPUT = 2
"""What the command was given cannot be used: an argument, a profile, a file, or a router
that is not there."""


def exit_code(error: Exception) -> int:
    """``EXIT_REFUSED`` for a question the running system did not answer or refused, else
    ``EXIT_BAD_INPUT``."""
    refused = isinstance(error, QueryError) and not isinstance(error, NoRouter)
    return EXIT_REFUSED if refused else EXIT_BAD_INPUT


def fail(error: Exception) -> int:
    """Say ``error`` in one line; its exit code (``exit_code``)."""
    print(error, file=sys.stderr)
    return exit_code(error)
