"""messages.lockstep: a stamp is answered once every topic has carried one as late."""

from __future__ import annotations

from messages.lockstep import AnswerStamps


def test_a_stamp_is_answered_when_every_topic_has_carried_one_as_late() -> None:
    stamps = AnswerStamps()
    names = ("vision/markers", "world/markers")
    assert stamps.missing(100, names) == list(names)
    stamps.note("vision/markers", 120)
    stamps.note("world/markers", 90)
    assert stamps.missing(100, names) == ["world/markers"] and not stamps.answered(100, names)
    stamps.note("world/markers", 100)
    stamps.note("vision/markers", 50)  # late news of an older stamp moves nothing back
    assert stamps.answered(100, names) and not stamps.answered(121, names)
    stamps.forget()
    assert stamps.missing(0, names) == list(names)
