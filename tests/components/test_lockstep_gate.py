"""components.lockstep_gate: a lockstep step waits for the commands of its stamp, a camera
frame for its answers before the sensors its latency reaches, and an answer overdue by the
timeout, or owed since before a component restarted, is counted and given up so the run goes on.

The gate is pure logic over a host clock it is given: here a clock the test moves by hand,
so no verdict depends on the machine's speed."""

from __future__ import annotations

from components.lockstep_gate import COMMANDS, FRAME_ANSWERS, RESTART_GRACE_S, LockstepGate
from messages import topics

MS = 1_000_000
TIMEOUT_S = 2.0


class HandClock:
    """Host seconds that move only when the test says."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def gate(
    latency_ns: int = 0, timeout_s: float = TIMEOUT_S
) -> tuple[LockstepGate, dict[str, int], HandClock]:
    counters: dict[str, int] = {}
    clock = HandClock()
    return LockstepGate(counters, latency_ns, lambda: timeout_s, clock), counters, clock


def test_the_answers_are_the_topic_tables_commands_and_frame_answers() -> None:
    assert COMMANDS == (topics.BASE_COMMAND.name, topics.ARM_COMMAND.name)
    assert FRAME_ANSWERS == (topics.VISION_MARKERS.name, topics.WORLD_MARKERS.name)


def test_a_step_waits_until_both_commands_of_its_stamp_are_in() -> None:
    lockstep, counters, clock = gate()
    lockstep.wait(COMMANDS, 20 * MS)
    assert lockstep.waiting and lockstep.check() is None
    assert lockstep.note(topics.BASE_COMMAND.name, 20 * MS) is None  # the arm's is missing
    assert lockstep.note(topics.ARM_COMMAND.name, 10 * MS) is None  # an older step's answer
    clock.now += 0.003
    done = lockstep.note(topics.ARM_COMMAND.name, 20 * MS)
    assert done is not None and done.stamp_ns == 20 * MS and not done.frame
    assert not lockstep.waiting
    assert counters["loop_us_median"] == 3000 and counters["lockstep_timeouts"] == 0


def test_commands_already_in_release_the_wait_at_once() -> None:
    lockstep, _, _ = gate()
    for name in COMMANDS:
        lockstep.note(name, 30 * MS)
    lockstep.wait(COMMANDS, 30 * MS)
    assert lockstep.check() is not None and not lockstep.waiting


def test_an_answer_overdue_by_the_timeout_is_counted_named_and_given_up() -> None:
    lockstep, counters, clock = gate()
    lockstep.wait(COMMANDS, 40 * MS)
    lockstep.note(topics.BASE_COMMAND.name, 40 * MS)
    clock.now += TIMEOUT_S  # at the deadline: not yet overdue
    assert lockstep.overdue() is None and lockstep.waiting
    clock.now += 0.001
    overdue = lockstep.overdue()
    assert overdue is not None
    awaited, missing, restarted = overdue
    assert awaited.stamp_ns == 40 * MS and missing == [topics.ARM_COMMAND.name]
    assert restarted is None
    assert counters["lockstep_timeouts"] == 1 and not lockstep.waiting
    assert lockstep.overdue() is None  # counted once


def test_the_timeout_is_read_when_a_wait_begins() -> None:
    counters: dict[str, int] = {}
    clock, timeout = HandClock(), [TIMEOUT_S]
    lockstep = LockstepGate(counters, 0, lambda: timeout[0], clock)
    timeout[0] = 0.5  # set while the simulator runs (parsimony param set)
    lockstep.wait(COMMANDS, 10 * MS)
    clock.now += 0.6
    assert lockstep.overdue() is not None


def test_a_frame_is_awaited_before_the_sensors_its_latency_reaches() -> None:
    lockstep, counters, clock = gate(latency_ns=30 * MS)
    lockstep.frame_taken(100 * MS)
    assert not lockstep.frame_due(120 * MS)  # within the latency: the loop runs on
    assert not lockstep.waiting
    clock.now += 0.004
    assert lockstep.frame_due(130 * MS)  # the estimator uses the frame now: wait for it
    assert lockstep.awaited is not None and lockstep.awaited.frame
    assert lockstep.awaited.stamp_ns == 100 * MS
    assert lockstep.note(topics.VISION_MARKERS.name, 100 * MS) is None
    done = lockstep.note(topics.WORLD_MARKERS.name, 100 * MS)
    assert done is not None and done.frame
    assert lockstep.unanswered is None and not lockstep.frame_pending()
    assert counters["frame_us_median"] == 4000 and counters["frame_wait_us_median"] == 0


def test_an_answered_frame_is_forgotten_and_holds_nothing() -> None:
    lockstep, counters, _ = gate(latency_ns=30 * MS)
    lockstep.frame_taken(100 * MS)
    for name in FRAME_ANSWERS:
        assert lockstep.note(name, 100 * MS) is None  # nothing was awaited
    assert "frame_us_median" in counters
    assert not lockstep.frame_due(200 * MS) and lockstep.unanswered is None


def test_the_next_frame_waits_for_the_last_ones_answers() -> None:
    lockstep, _, _ = gate(latency_ns=50 * MS)
    assert not lockstep.frame_pending()
    lockstep.frame_taken(100 * MS)
    assert lockstep.frame_pending()
    assert lockstep.awaited is not None and lockstep.awaited.topics == FRAME_ANSWERS


def test_an_overdue_frame_is_given_up_and_the_next_one_goes() -> None:
    lockstep, counters, clock = gate(latency_ns=0)
    lockstep.frame_taken(100 * MS)
    lockstep.wait(FRAME_ANSWERS, 100 * MS)
    lockstep.note(topics.VISION_MARKERS.name, 100 * MS)
    clock.now += TIMEOUT_S + 0.1
    overdue = lockstep.overdue()
    assert overdue is not None and overdue[1] == [topics.WORLD_MARKERS.name]
    assert counters["lockstep_timeouts"] == 1
    assert lockstep.unanswered is None and not lockstep.frame_pending()


def test_a_restart_gives_up_what_was_awaited_before_it_and_nothing_after() -> None:
    """A component restarted: the answers of the wait under way and of the frame not yet answered
    may still come within the grace (the others' do), and are given up after it, named with the
    component, though the timeout is far; a step sent after the restart waits as before."""
    lockstep, counters, clock = gate(latency_ns=30 * MS, timeout_s=30.0)  # an experiment's
    lockstep.forsake("vision_tracker")  # nothing awaited: nothing given up
    lockstep.frame_taken(100 * MS)
    lockstep.wait(COMMANDS, 110 * MS)
    lockstep.forsake("state_estimator")
    clock.now += RESTART_GRACE_S  # the grace: the answers may still come
    assert lockstep.overdue() is None and lockstep.waiting
    clock.now += 0.001
    overdue = lockstep.overdue()
    assert overdue is not None
    awaited, missing, restarted = overdue
    assert (awaited.stamp_ns, missing, restarted) == (110 * MS, list(COMMANDS), "state_estimator")
    assert lockstep.frame_due(130 * MS)  # the frame sent before the restart is waited for...
    overdue = lockstep.overdue()  # ...and given up, the grace over
    assert overdue is not None and overdue[0].frame and overdue[2] == "state_estimator"
    lockstep.wait(COMMANDS, 140 * MS)  # sent after the restart
    clock.now += RESTART_GRACE_S + 0.1
    assert lockstep.overdue() is None and lockstep.waiting
    assert counters["lockstep_timeouts"] == 2


def test_answers_that_come_within_a_restarts_grace_end_the_wait() -> None:
    lockstep, counters, clock = gate()
    lockstep.wait(COMMANDS, 50 * MS)
    lockstep.forsake("supervisor")  # answers nothing the gate awaits
    clock.now += 0.01
    lockstep.note(COMMANDS[0], 50 * MS)
    assert lockstep.note(COMMANDS[1], 50 * MS) is not None and not lockstep.waiting
    assert counters["lockstep_timeouts"] == 0
