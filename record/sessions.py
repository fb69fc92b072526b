"""A recorded session in memory: every message of each topic, in log-time order."""

from __future__ import annotations

import functools
import os
from collections.abc import Collection
from pathlib import Path

from record.session_reader import read_session


def load_session(path: Path, only: Collection[str] | None = None) -> dict[str, list]:
    """Topic name -> the messages recorded on it (views and unknown keys left out); given
    ``only`` (topic names), those topics alone, nothing else decoded or held.

    The last session loaded is kept: loading the same file again, unchanged (its inode, size
    and modification time), gives its messages (immutable) without reading it again, as a
    study's run does once its experiment has judged the recording."""
    found = os.stat(path)
    identity = (found.st_dev, found.st_ino, found.st_size, found.st_mtime_ns)
    wanted = None if only is None else frozenset(only)
    return {name: list(messages) for name, messages in _loaded(path, identity, wanted).items()}


@functools.lru_cache(maxsize=1)
def _loaded(path: Path, identity: tuple[int, ...], only: frozenset[str] | None) -> dict[str, list]:
    session: dict[str, list] = {}
    for recorded in read_session(path, only):
        if recorded.topic_name is not None and recorded.message is not None:
            session.setdefault(recorded.topic_name, []).append(recorded.message)
    return session
