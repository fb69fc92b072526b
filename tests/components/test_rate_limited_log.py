"""Warnings that could come in floods logged once, then summarised (components.rate_limited_log)."""

from __future__ import annotations

import logging

import pytest

from components import rate_limited_log
from components.rate_limited_log import RateLimitedLog


def test_repeated_warnings_are_logged_once_then_summarised(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    now = [0]
    monkeypatch.setattr(rate_limited_log.time, "monotonic_ns", lambda: now[0])
    warnings = RateLimitedLog(logging.getLogger("test"), interval_s=5.0)
    for step_s in (0, 1, 2, 3, 6, 7):
        now[0] = step_s * 1_000_000_000
        warnings.warning("rejected.robot/state", f"bad message at {step_s} s")
    warnings.warning("errors.robot/state", "handler failed")
    assert [record.getMessage() for record in caplog.records] == [
        "bad message at 0 s",
        "bad message at 6 s (3 more since the last report)",
        "handler failed",
    ]
