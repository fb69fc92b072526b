"""Waiting for the components of a running system to come alive, saying what is awaited: the
router first (a launch started in the background may not have opened it yet), then the
components whose liveliness token is not there yet."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence

import zenoh

from launch.query import NoRouter, QueryError, Target, live_components
from messages import topics

ROUTER_RETRY_S = 0.2
"""How often an unreachable router is tried again."""
SAY_EVERY_S = 1.0
"""What is awaited is said at most this often: when it changes..."""
REMIND_S = 5.0
"""...or, when nothing changes, again after this long."""


class NotAlive(QueryError):
    """Some components were not alive when the wait ended."""


class _Say:
    """Says a line at most every ``SAY_EVERY_S`` when it changes, else every ``REMIND_S``."""

    def __init__(self, say: Callable[[str], None], timeout_s: float) -> None:
        self._say = say
        self._timeout_s = timeout_s
        self._started = time.monotonic()
        self._last: tuple[float, str] | None = None
        self.said = False

    def __call__(self, text: str) -> None:
        now = time.monotonic()
        if self._last is not None:
            since, last = now - self._last[0], self._last[1]
            if since < SAY_EVERY_S or (since < REMIND_S and text == last):
                return
        self._last = (now, text)
        self.said = True
        self._say(f"{text} ({now - self._started:.0f} s of at most {self._timeout_s:g})")


def wait_alive(
    target: Target, names: Sequence[str], timeout_s: float, say: Callable[[str], None]
) -> None:
    """Return once every component of ``names`` is alive in ``target``'s namespace; raise
    ``NotAlive`` naming those that are not after ``timeout_s``. What it waits for goes to
    ``say``: the router while it cannot be reached, then the components still missing."""
    deadline = time.monotonic() + timeout_s
    tell = _Say(say, timeout_s)
    where = ", ".join(target.zenoh.connect_endpoints)
    while True:
        try:
            session = target.open()
            break
        except NoRouter:
            if time.monotonic() >= deadline:
                raise NotAlive(
                    f"no router at {where} after {timeout_s:g} s (is the profile "
                    f"launched?); not alive: {', '.join(names)}"
                ) from None
            tell(f"waiting for the router at {where} to listen")
            time.sleep(ROUTER_RETRY_S)
    with session:
        missing = _wait_tokens(session, target.namespace, names, deadline, tell)
    if missing:
        raise NotAlive(
            f"not alive after {timeout_s:g} s: {', '.join(missing)} "
            f"({len(names) - len(missing)} of {len(names)} alive)"
        )
    if tell.said:
        say(f"all {len(names)} components alive")


def _wait_tokens(
    session: zenoh.Session, namespace: str, names: Sequence[str], deadline: float, tell: _Say
) -> list[str]:
    """The components of ``names`` still without a liveliness token at ``deadline``, or []
    as soon as all have one."""
    alive: set[str] = set()
    changed = threading.Condition()

    def on_token(sample: zenoh.Sample) -> None:
        name = topics.component_of_liveliness_key(namespace, str(sample.key_expr))
        with changed:
            (alive.add if sample.kind == zenoh.SampleKind.PUT else alive.discard)(name)
            changed.notify_all()

    watcher = session.liveliness().declare_subscriber(
        topics.liveliness_selector(namespace), on_token, history=True
    )
    try:
        present = live_components(session, namespace)  # those alive before it subscribed
        with changed:
            alive.update(present)
            while missing := [name for name in names if name not in alive]:
                left = deadline - time.monotonic()
                if left <= 0:
                    return missing
                tell(
                    f"waiting for {', '.join(missing)} to come alive, "
                    f"{len(names) - len(missing)} of {len(names)} so far"
                )
                changed.wait(min(SAY_EVERY_S, left))
            return []
    finally:
        watcher.undeclare()
