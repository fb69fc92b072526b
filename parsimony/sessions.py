"""A recorded session in memory: every message of each topic, in log-time order."""

from __future__ import annotations

from pathlib import Path

from record.session_file import read_session


def load_session(path: Path) -> dict[str, list]:
    """Topic name -> the messages recorded on it (views and unknown keys left out)."""
    session: dict[str, list] = {}
    for recorded in read_session(path):
        if recorded.topic_name is not None and recorded.message is not None:
            session.setdefault(recorded.topic_name, []).append(recorded.message)
    return session
