"""A command that runs until stopped takes SIGINT and SIGTERM even when it inherited SIGINT
ignored, as a shell's background job does (``cmd &``, ``nohup``): the first is noted or raised,
the others ignored while it cleans up, and the handlers it found come back after."""

from __future__ import annotations

import signal
import threading

import pytest

from parsimony.stop_signals import Interrupted, stop_signals


def signalled(signum: signal.Signals) -> None:
    """``signum`` sent to this (the main) thread: its handler has run when this returns."""
    signal.pthread_kill(threading.get_ident(), signum)


@pytest.fixture
def sigint_ignored():
    """SIGINT ignored in this process, as a background job inherits it."""
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    yield
    signal.signal(signal.SIGINT, previous)


def test_a_sigint_inherited_ignored_is_taken_and_the_ignoring_comes_back(sigint_ignored) -> None:
    with stop_signals() as stop:
        signalled(signal.SIGINT)
        assert stop.wait() == "SIGINT"
        signalled(signal.SIGTERM)  # a second stop signal: ignored
        assert stop.signal == "SIGINT"
    assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN
    assert signal.getsignal(signal.SIGTERM) == signal.SIG_DFL


def test_raised_it_names_the_signal_and_its_exit_code(sigint_ignored) -> None:
    with pytest.raises(Interrupted) as raised, stop_signals(raising=True):
        signalled(signal.SIGTERM)
    assert (raised.value.signal, raised.value.exit_code) == ("SIGTERM", 143)
    with pytest.raises(Interrupted) as raised, stop_signals(raising=True) as stop:
        try:
            signalled(signal.SIGINT)
        finally:  # the cleanup of the block is not interrupted by a second one
            signalled(signal.SIGTERM)
            cleaned = True
    assert cleaned and stop.signal == "SIGINT" and raised.value.exit_code == 130
    assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN
