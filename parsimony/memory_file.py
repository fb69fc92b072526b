"""A file in memory that a child process reads at a path, leaving nothing behind."""

from __future__ import annotations

import os
from pathlib import Path


def memory_file(name: str, text: str) -> tuple[int, Path]:
    """A file in memory (``memfd_create``) holding ``text``, and the path a child that
    inherits its descriptor (``pass_fds``) reads it at: nothing is left behind, whatever kills
    this process."""
    descriptor = os.memfd_create(name)
    os.write(descriptor, text.encode())
    return descriptor, Path(f"/proc/self/fd/{descriptor}")
