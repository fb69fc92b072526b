"""A recorded session in memory (record/sessions.py): each topic's messages in log-time order,
the views and the keys of no topic left out, or the topics asked for alone."""

from __future__ import annotations

from pathlib import Path

from messages import topics
from messages.clock import Clock
from record.session_file import SessionWriter
from record.sessions import load_session
from tests.record.session_messages import NAMESPACE, image, state


def test_a_session_holds_each_topics_messages_and_nothing_else(tmp_path: Path) -> None:
    path = tmp_path / "session.mcap"
    with SessionWriter(path) as writer:
        for stamp in (3, 1, 2):
            writer.write(topics.ROBOT_STATE.key(NAMESPACE), state(stamp, seq=stamp))
        writer.write(topics.CAMERA_IMAGE.key(NAMESPACE), image(4), views=True)
        writer.write(topics.SIM_CLOCK.key(NAMESPACE), Clock(stamp_ns=5))
    session = load_session(path)
    assert set(session) == {"robot/state", "camera/image", "sim/clock"}
    assert [m.header.seq for m in session["robot/state"]] == [1, 2, 3]
    assert session["camera/image"] == [image(4)]
    only = load_session(path, only={"sim/clock"})
    assert only == {"sim/clock": [Clock(stamp_ns=5)]}
