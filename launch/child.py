"""One supervised component: its process and its bookkeeping."""

from __future__ import annotations

import subprocess
from dataclasses import dataclass

from launch.fork_server import Served
from profiles.profile import ComponentSpec

Process = subprocess.Popen[str] | Served
"""A component's process: forked by the launch's fork server, or a new interpreter."""


@dataclass
class Child:
    """One component's process and its restart bookkeeping."""

    spec: ComponentSpec
    process: Process | None = None
    waiting: bool = True
    """Not started yet: it waits for the components it starts ``after``."""
    started_at: float = 0.0
    restarts: int = 0
    restart_at: float | None = None
    done: bool = False
    failed: bool = False
    alive: bool = False
    """Whether the current process's liveliness token is present."""
    answered_at: float = 0.0
    """When it last answered a status query, or came alive (the watchdog's reference)."""
    state: str = "running"
    """Its ``state`` as last reported (a component comes alive running)."""
    stopping: bool = False
    """Sent SIGTERM by the stop: its token going is no loss."""
