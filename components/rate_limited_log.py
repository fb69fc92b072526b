"""Warnings that could come in floods (malformed messages, failing handlers), logged sparingly."""

from __future__ import annotations

import logging
import time

SUMMARY_INTERVAL_S = 5.0
"""Repeated warnings of one kind are summarised at most this often."""


class RateLimitedLog:
    """Logs the first warning of a kind, then at most one summary per interval."""

    def __init__(self, logger: logging.Logger, interval_s: float = SUMMARY_INTERVAL_S) -> None:
        self._logger = logger
        self._interval_ns = round(interval_s * 1e9)
        self._last_ns: dict[str, int] = {}
        self._suppressed: dict[str, int] = {}

    def warning(self, kind: str, message: str, exc_info: bool = False) -> None:
        """Log ``message`` unless a ``kind`` warning was logged less than an interval ago."""
        now = time.monotonic_ns()
        last = self._last_ns.get(kind)
        if last is not None and now - last < self._interval_ns:
            self._suppressed[kind] = self._suppressed.get(kind, 0) + 1
            return
        self._last_ns[kind] = now
        suppressed = self._suppressed.pop(kind, 0)
        suffix = f" ({suppressed} more since the last report)" if suppressed else ""
        self._logger.warning("%s%s", message, suffix, exc_info=exc_info)
