"""Several components of one profile in one process (a profile's ``processes: shared``).

    python -m components.container --profile P --names a,b,c [--ahead]

runs each named component as ``python -m components.<module>`` would, with its own ``Node`` and
threads, in this one process: the interpreter and the libraries they import (NumPy, Zenoh,
OpenCV, HiGHS) load once instead of once per component, and they share one Zenoh session (unless
the profile's components authenticate or are clients), so that a sample between two of them is
handed over in the session, not copied over a socket. They start in the order given (with
``--ahead``, once a line on its input says so: the launcher starts the process before its router
opens and the recorders start, so that it loads its modules meanwhile) and close in the reverse
order, on SIGINT, SIGTERM, the end of the launcher or the ``fail`` of one of them; each keeps
what its next start takes back in the launch's runtime directory
(``messages.process.runtime_dir``), as a component in a process of its own does.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence
from pathlib import Path

from components.process_entry import StopRequested, serve, start_logging
from components.runtime import Component
from messages.process import EXIT_CONFIG_ERROR, params_file
from profiles.profile import ProfileError, load_profile

MODULE = "components.container"


def command(profile: Path, names: Sequence[str], ahead: bool) -> list[str]:
    """The command line running components ``names`` of ``profile`` in one process; ``ahead``:
    once a line on its input says so, after loading their modules."""
    return [
        sys.executable,
        "-m",
        MODULE,
        "--profile",
        str(profile),
        "--names",
        ",".join(names),
        *(["--ahead"] if ahead else []),
    ]


def component_class(module_path: str) -> type[Component]:
    """The one ``Component`` class a component module defines (the one it runs)."""
    module = importlib.import_module(module_path)
    found = [
        value
        for value in vars(module).values()
        if isinstance(value, type)
        and issubclass(value, Component)
        and value.__module__ == module.__name__
    ]
    if len(found) != 1:
        raise ProfileError(f"{module_path} defines {len(found)} components, not one")
    return found[0]


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--profile", required=True, help="the deploy profile (YAML)")
    parser.add_argument("--names", required=True, help="the components to run, comma-separated")
    parser.add_argument("--ahead", action="store_true", help="start them on a line of input")
    parser.add_argument("--log-level", default="INFO", help="DEBUG, INFO, WARNING or ERROR")
    args = parser.parse_args(argv)
    start_logging(args.log_level)
    try:
        profile = load_profile(args.profile)
        specs = [profile.component(name) for name in args.names.split(",")]
        classes = [component_class(spec.module_path) for spec in specs]
    except (ProfileError, KeyError) as error:
        print(f"{args.profile}: {error}", file=sys.stderr)
        return EXIT_CONFIG_ERROR
    try:
        if args.ahead and not sys.stdin.readline():
            return 0  # the launcher stopped before it said to start
    except StopRequested:
        return 0
    members = [
        (cls, spec.name, params_file(spec.name)) for cls, spec in zip(classes, specs, strict=True)
    ]
    return serve(args.profile, members)


if __name__ == "__main__":
    sys.exit(main())
