"""The contract of a component process with whoever starts it and asks it questions.

How it is started (``command``), what its exit codes mean, what the environment tells it, and
how a parameter's value travels in a query reply. The launcher (``deploy``) and the runtime
(``components``) both follow it; neither imports the other.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from messages.base import Finite

ParamValue = bool | int | Finite | str | tuple[Finite, ...] | tuple[tuple[Finite, ...], ...]
"""A parameter's value: a flag, a number, a word, a vector of numbers or a list of vectors;
pydantic keeps the exact type (``True`` stays a bool, ``1`` an int)."""

EXIT_CONFIG_ERROR = 2
"""Exit code of a component refused by its configuration; the launcher never restarts it."""

EXIT_FOR_GOOD = 3
"""Exit code of a component that cannot go on (a recorder whose disk is full); the launcher
never restarts it."""

PARENT_PID_ENV = "PARSIMONY_PARENT_PID"
"""Set by whoever starts a process of ours as its child (the launcher its components,
``parsimony record`` its recorder, ``parsimony experiment`` its launcher): a child whose parent
is no longer that pid stops (a launcher stops its components first), so nothing runs on
after its parent is killed."""


def parent_gone() -> bool:
    """This process was started by one that named itself (``PARENT_PID_ENV``), which is gone
    (the process is now another's child)."""
    parent = os.environ.get(PARENT_PID_ENV)
    return parent is not None and os.getppid() != int(parent)


RUNTIME_DIR_ENV = "PARSIMONY_RUNTIME_DIR"
"""Set by the launcher for every process it starts (one component's, or a shared one's): the
launch's runtime directory, removed when the launch ends, where each component keeps what its
next start takes back (``params_file``; the stop latch's ``stop/``)."""


def runtime_dir() -> Path | None:
    """The launch's runtime directory (``RUNTIME_DIR_ENV``); None for a process no launcher
    started."""
    folder = os.environ.get(RUNTIME_DIR_ENV)
    return Path(folder) if folder else None


def params_file(name: str) -> Path | None:
    """Where component ``name`` keeps the parameters set while it runs, and takes them back
    from when it is started again (a restart keeps them); None without a launcher."""
    folder = runtime_dir()
    return folder / f"{name}.json" if folder else None


def command(module_path: str, profile: Path, name: str) -> list[str]:
    """The command line of component ``name`` of ``profile``, running ``module_path``."""
    return [sys.executable, "-m", module_path, "--profile", str(profile), "--name", name]


def stop(child: subprocess.Popen, signum: int, timeout_s: float | None) -> int:
    """Send ``signum`` to ``child`` and wait ``timeout_s`` (None: as long as it takes) for it,
    then kill it; its exit code."""
    child.send_signal(signum)
    try:
        return child.wait(timeout_s)
    except subprocess.TimeoutExpired:
        child.kill()
        return child.wait()


def encode_value(value: ParamValue) -> bytes:
    """A parameter value as a reply payload (JSON)."""
    return json.dumps(value).encode()


def decode_value(payload: bytes) -> ParamValue:
    """The parameter value in a reply payload."""
    return json.loads(payload)
