"""The control station's Zenoh session (``view.control_station``): an operation on it that
fails with a Zenoh error (the session closed, or a panic in Zenoh) is logged as an error and
counted (``errors``), and run once more on a new session opened from the profile, on which
what the station declared is declared again (``failed`` says why none could be opened)."""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Any, TypeVar

import zenoh

from launch.tool_clock import ToolClock
from launch.zenoh_error import is_session_error, zenoh_error_text
from profiles.profile import Profile

log = logging.getLogger("parsimony.view")
T = TypeVar("T")


class SessionFailed(Exception):
    """The station's Zenoh session failed and no new one could be opened."""


class StationSession:
    """``session`` (``user``'s, of ``profile``), and what ``declare(session)`` declares on it
    (undeclared with ``close``); ``lock`` is the station's, held while a new one opens."""

    def __init__(
        self,
        session: zenoh.Session,
        profile: Profile,
        user: str,
        declare: Callable[[zenoh.Session], list[Any]],
        lock: threading.Lock,
    ) -> None:
        self.session, self._profile, self._user = session, profile, user
        self._declare, self._lock = declare, lock
        self.errors = 0
        self.failed = ""
        """Why the session failed for good (a new one could not be opened)."""
        self._opened: list[zenoh.Session] = []
        """The sessions opened here (after a failure), closed with it."""
        self._declared = declare(session)

    def run(self, operation: Callable[[zenoh.Session], T]) -> T:
        """``operation`` on the session; after a Zenoh error, once more on a new one
        (``SessionFailed`` if none can be opened, or it fails there too)."""
        session = self.session
        try:
            return operation(session)
        except BaseException as error:
            if not is_session_error(error):
                raise
            self._reopen(session, error)
        try:
            return operation(self.session)
        except BaseException as error:
            if not is_session_error(error):
                raise
            raise SessionFailed(self._failure(zenoh_error_text(error))) from None

    def close(self) -> None:
        self._undeclare()
        for session in self._opened:
            session.close()
        self._opened = []

    def _undeclare(self) -> None:
        for declared in self._declared:
            try:
                if isinstance(declared, ToolClock):
                    declared.close()
                else:
                    declared.undeclare()
            except BaseException as error:
                if not is_session_error(error):
                    raise
        self._declared = []

    def _reopen(self, failed: zenoh.Session, error: BaseException) -> None:
        """Say that ``failed`` failed, and open a new session in its place (unless another
        thread did already)."""
        with self._lock:
            if self.session is not failed:
                return
            self.errors += 1
            log.error(
                "view: the control station's Zenoh session failed (%s); opening a new one",
                zenoh_error_text(error),
            )
            self._undeclare()
            try:
                self.session = zenoh.open(self._profile.zenoh.client_config(self._user))
                self._opened.append(self.session)
                self._declared = self._declare(self.session)
            except BaseException as opening:
                if not is_session_error(opening):
                    raise
                raise SessionFailed(self._failure(zenoh_error_text(opening))) from None
            self.failed = ""
            log.warning("view: the control station goes on on a new Zenoh session")

    def _failure(self, reason: str) -> str:
        self.failed = f"the view's Zenoh session failed: {reason}"
        log.error("view: %s", self.failed)
        return self.failed
