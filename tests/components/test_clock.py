"""Clocks and timers: periods on monotonic or simulated time, skipped periods, clock resets."""

from __future__ import annotations

import time

import pytest

from components.clock import STALL_CHECK_S, SimClock, Timers, WallClock

MS = 1_000_000


def test_timers_fire_on_simulated_time_only() -> None:
    clock = SimClock()
    timers = Timers(clock)
    fired: list[int] = []
    timers.add(0.1, lambda: fired.append(clock.now_ns()))
    assert timers.wait_s() == STALL_CHECK_S  # wakes to notice a clock that stopped
    clock.advance(99 * MS)
    assert timers.due() == []
    clock.advance(100 * MS)
    for timer in timers.due():
        timer.callback()
    assert fired == [100 * MS]


def test_missed_periods_are_skipped_not_replayed() -> None:
    clock = SimClock()
    timers = Timers(clock)
    (timer,) = [timers.add(0.1, lambda: None)]
    clock.advance(1050 * MS)
    assert timers.due() == [timer]
    assert timer.deadline_ns == 1150 * MS
    assert timers.due() == []


def test_a_clock_set_back_reschedules_from_the_new_time() -> None:
    clock = SimClock()
    timers = Timers(clock)
    clock.advance(10_000 * MS)
    timer = timers.add(0.1, lambda: None)
    clock.advance(10_100 * MS)
    assert timers.due() == [timer]
    clock.advance(5 * MS)
    timers.due()
    assert timer.deadline_ns == 105 * MS


def test_wall_timers_report_how_long_to_wait() -> None:
    timers = Timers(WallClock())
    assert timers.wait_s() is None
    timers.add(60.0, lambda: None)
    assert 59.0 < timers.wait_s() <= 60.0
    assert timers.due() == []


def test_a_period_must_be_positive() -> None:
    with pytest.raises(ValueError, match="must be > 0 s"):
        Timers(WallClock()).add(0.0, lambda: None)


def test_a_sim_clock_measures_how_long_it_has_not_moved() -> None:
    clock = SimClock()
    clock.advance(5 * MS)
    time.sleep(0.05)
    assert clock.stalled_s() >= 0.05
    clock.advance(5 * MS)  # the same stamp again: still stalled
    assert clock.stalled_s() >= 0.05
    clock.advance(6 * MS)
    assert clock.stalled_s() < 0.05


def test_a_paused_simulators_held_time_is_not_a_stall() -> None:
    clock = SimClock()
    clock.advance(5 * MS)
    time.sleep(0.05)
    clock.advance(5 * MS, paused=True)  # the same stamp, held on purpose
    assert clock.stalled_s() < 0.05
    time.sleep(0.05)
    clock.advance(5 * MS)  # no longer paused, and not moving
    assert clock.stalled_s() >= 0.05


def test_a_lockstep_simulators_held_time_is_not_a_stall() -> None:
    """In lockstep the simulator's time stands while the loop answers its step: a component
    that took that for a stall would command zero at the step's stamp, and the simulator would
    take that zero for the controller's answer (a rerun would then differ from its run)."""
    clock = SimClock()
    clock.advance(5 * MS, lockstep=True)
    time.sleep(0.05)
    assert clock.stalled_s() == 0.0
    clock.advance(5 * MS)  # the simulator left lockstep, and its time does not move
    time.sleep(0.05)
    assert clock.stalled_s() >= 0.05


def test_an_alarm_fires_once_after_its_last_set_and_not_after_a_cancel() -> None:
    clock = SimClock()
    timers = Timers(clock)
    alarm = timers.alarm(lambda: None)
    clock.advance(1000 * MS)
    assert timers.due() == []  # never set
    alarm.set(0.2)
    clock.advance(1150 * MS)
    alarm.set(0.2)  # a command came: the deadline moves on
    clock.advance(1300 * MS)
    assert timers.due() == []
    clock.advance(1350 * MS)
    assert timers.due() == [alarm]
    clock.advance(2000 * MS)
    assert timers.due() == []  # once
    alarm.set(0.1)
    alarm.cancel()
    clock.advance(3000 * MS)
    assert timers.due() == []


def test_a_wall_alarm_is_what_the_handler_thread_waits_for() -> None:
    timers = Timers(WallClock())
    timers.add(60.0, lambda: None)
    timers.alarm(lambda: None).set(0.2)
    assert 0.0 < timers.wait_s() <= 0.2
