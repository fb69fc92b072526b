"""A session's span and the stamps far outside it (record/session_span.py): a session parted by
the rule, and the one line that names what was left out. (``Span``'s rule itself is tested with
the far stamps of a recording, in test_far_stamps.)"""

from __future__ import annotations

from messages.clock import Clock
from record.session_span import FAR_NS, parted


def test_a_session_is_parted_into_its_span_and_what_lies_far_outside_by_topic() -> None:
    start = 40 * FAR_NS  # host time; the odd stamps are near 0 (only stamps matter here)
    session = {
        "sim/clock": [Clock(stamp_ns=start + i * 10**9) for i in range(10)],
        "robot/state": [Clock(stamp_ns=2 * 10**9), Clock(stamp_ns=start), Clock(stamp_ns=10**9)],
        "camera/image": [Clock(stamp_ns=start + 10**9)],
    }
    split = parted(session)
    assert split.span == (start, start + 9 * 10**9)
    assert [len(split.kept[topic]) for topic in session] == [10, 1, 1]
    assert list(split.outside) == ["robot/state"] and len(split.outside["robot/state"]) == 2
    assert split.line() == (
        f"stamped far outside the session ({start / 1e9:.3f} to {(start + 9e9) / 1e9:.3f} s): "
        "2 messages of robot/state (at 1.000 s first)"
    )


def test_a_session_wholly_inside_its_span_has_no_line() -> None:
    split = parted({"sim/clock": [Clock(stamp_ns=k) for k in (5, 7)]})
    assert split.span == (5, 7) and split.outside == {} and split.line() is None
