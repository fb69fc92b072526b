"""A recorded session in memory: every message of each topic, in log-time order."""

from __future__ import annotations

from collections.abc import Collection
from pathlib import Path

from record.session_reader import read_session


def load_session(path: Path, only: Collection[str] | None = None) -> dict[str, list]:
    """Topic name -> the messages recorded on it (views and unknown keys left out); given
    ``only`` (topic names), those topics alone, nothing else decoded or held."""
    session: dict[str, list] = {}
    for recorded in read_session(path, only):
        if recorded.topic_name is not None and recorded.message is not None:
            session.setdefault(recorded.topic_name, []).append(recorded.message)
    return session
