"""The start of a child's process: its command, its environment, its output forwarded."""

from __future__ import annotations

import os
import subprocess
import threading
from pathlib import Path

from components import container
from launch.child import Process
from launch.fork_server import ForkServer
from launch.forked import ChildOptions
from launch.output import Output
from messages import process
from messages.process import PARENT_PID_ENV, RUNTIME_DIR_ENV
from profiles.profile import ComponentSpec


def spawn(
    group: list[ComponentSpec],
    profile_path: Path,
    kept_params: Path,
    pass_fds: tuple[int, ...],
    output: Output,
    ahead: bool = False,
    server: ForkServer | None = None,
) -> Process:
    """The process of ``group`` (one component, or shared ones: ``components.container``,
    waiting for a word on its input when ``ahead``) and the threads forwarding its output
    (``forward``).

    Its parameters set at run time are kept under ``kept_params``; it inherits ``pass_fds``
    and runs in its own session, stopping by itself when its parent is gone. It is forked by
    ``server`` (``launch.fork_server``: its parent then) if there is one that serves, else it
    is a new interpreter, the launcher's child."""
    names = [spec.name for spec in group]
    env = dict(
        os.environ,
        PYTHONUNBUFFERED="1",
        **{PARENT_PID_ENV: str(os.getpid()), RUNTIME_DIR_ENV: str(kept_params)},
    )
    if len(group) > 1 or ahead:
        command = container.command(profile_path, names, ahead)
    else:
        spec = group[0]
        command = process.command(spec.module_path, profile_path, spec.name)
    how: ChildOptions = {
        "stdin": subprocess.PIPE if ahead else subprocess.DEVNULL,
        "stdout": subprocess.PIPE,
        "stderr": subprocess.PIPE,
        "env": env,
        "start_new_session": True,
        "pass_fds": pass_fds,
    }
    popen = None if server is None else server.spawn(command[2:], **how)  # [python, -m, ...]
    if popen is None:
        popen = subprocess.Popen(command, text=True, errors="replace", **how)
    forward(popen, names, output)
    return popen


def forward(popen: Process, names: list[str], output: Output) -> None:
    """Threads forwarding the output of the process of components ``names``, prefixed."""
    prefix = "+".join(names)
    for pipe, stream in ((popen.stdout, output.out), (popen.stderr, output.err)):
        threading.Thread(target=output.forward, args=(pipe, stream, prefix), daemon=True).start()
