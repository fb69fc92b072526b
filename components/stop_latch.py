"""The latched emergency stop, as each component that moves the robot, or asks it to, holds it.

``parsimony stop`` (or the control station's stop) publishes a ``StopState`` on
``control/stop``; ``parsimony release`` publishes the release. Each holder takes a state newer
than the one it holds (the giver's wall clock) and keeps it until a newer one: a lost router
changes nothing, each holder stays as it was. A holder that starts (a restarted driver) first
takes the newest stop kept on disk by the holders of its launch (``kept_dir``), then asks
every running component's status for the stop it holds and takes the newest, so it starts
stopped when the namespace is, even with the router away and nobody to answer; its
subscription is declared before it asks, so a stop given meanwhile is not missed. A stopped
holder puts its stop again every ``REMIND_S``, so that a holder that missed it (its question
unanswered, a partition) takes it then.

The state is set on the Zenoh thread the moment it arrives, so a command the handler thread
takes after it is refused (``refuses``); ``on_change`` then runs on the handler thread (a
driver commands zero there). The holder's status carries the state (``ComponentStatus.stop``).
"""

from __future__ import annotations

import logging
import os
import threading
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path

import zenoh

from components.runtime import Node
from messages import codec, topics
from messages.header import Header
from messages.process import runtime_dir
from messages.stop import StopState
from profiles.profile import Profile

ASK_TIMEOUT_S = 1.0
"""How long a starting holder waits for the running components' statuses."""
ASK_WAIT_S = 0.15
"""How long a starting holder waits to know of another component's status before it asks (a
few ms when one runs; the whole wait, on a launch's critical path, when none does yet)."""
REMIND_S = 1.0
"""How often a stopped holder puts its stop again (``StopLatch._remind``)."""

NEVER_STOPPED = StopState(header=Header(stamp_ns=0, frame="", seq=0, source=""), stopped=False)
"""What a holder holds before any stop: released, older than any state given."""

UNREADABLE_SOURCE = "stop_latch"
"""Who gave the stop a holder starts with when a kept stop cannot be read (``_recall``)."""

REFUSED = "refused_while_stopped"
"""The counter of the commands (and goals) a holder refused while stopped."""

COMMAND_TOPICS = (topics.CONTROL_GOAL.name, topics.GOAL_REQUEST.name)
"""Who may put on these may command the robot, and so release the stop (``release_refusal``)."""

log = logging.getLogger("components")


def stop_text(state: StopState) -> str:
    """``stopped by alice (a hand in the way)`` or ``released by bob``."""
    verb = "stopped" if state.stopped else "released"
    return f"{verb} by {state.header.source}" + (f" ({state.reason})" if state.reason else "")


def kept_dir() -> Path | None:
    """Where the holders of this launch keep the stop each holds, one ``NAME.json`` each:
    ``stop/`` in the launch's runtime directory (``messages.process.runtime_dir``, removed when
    the launch ends), whether the holder has a process of its own or shares one; None for a
    component that no launcher started."""
    folder = runtime_dir()
    return folder / "stop" if folder else None


class StopLatch:
    """The stop a component holds; ``on_change(state)`` runs on its handler thread at each
    change (and once at start when it starts stopped)."""

    def __init__(self, node: Node, on_change: Callable[[StopState], None] | None = None) -> None:
        self.node = node
        self.state = NEVER_STOPPED
        self._on_change = on_change
        self._lock = threading.Lock()
        node.stop = self.state
        node.counters[REFUSED] = 0
        on_sample = zenoh.handlers.Callback(self._on_sample, indirect=False)
        self._subscriber = node.session.declare_subscriber(
            topics.CONTROL_STOP.key(node.namespace), on_sample
        )
        self._publisher = node.session.declare_publisher(topics.CONTROL_STOP.key(node.namespace))
        node.timer(REMIND_S, self._remind)
        self._kept = kept_dir()
        self._recall()
        self._ask()

    @property
    def stopped(self) -> bool:
        """Whether the namespace is stopped, as this holder knows it."""
        return self.state.stopped

    def refuses(self) -> bool:
        """True (and counted in ``refused_while_stopped``) while stopped: the caller drops the
        command or goal it holds."""
        if not self.state.stopped:
            return False
        self.node.count(REFUSED)
        return True

    def take(self, state: StopState) -> bool:
        """Hold ``state`` if it is newer than the one held; whether it was (any thread)."""
        with self._lock:
            if state.header.stamp_ns <= self.state.header.stamp_ns:
                return False
            changed = state.stopped != self.state.stopped
            self.state = state
            self.node.stop = state
        if changed or state.stopped:
            self.node.post(partial(self._changed, state))
        return True

    def _changed(self, state: StopState) -> None:
        """Handler thread: say it, tell the component, and keep it on disk."""
        log.warning("%s: %s", self.node.name, stop_text(state))
        if self._on_change is not None:
            self._on_change(state)
        self._keep(state)

    def _keep(self, state: StopState) -> None:
        """Write the state held to this holder's file in ``kept_dir`` (whole, or not at all),
        for the holder started after it on this computer (``_recall``)."""
        if self._kept is None:
            return
        path = self._kept / f"{self.node.name}.json"
        part = path.with_name(f".{path.name}.part")
        try:
            self._kept.mkdir(exist_ok=True)
            part.write_text(state.model_dump_json())
            os.replace(part, path)
        except OSError as error:
            self.node.count("stop_file_errors")
            self.node.warn("stop_file_errors", f"cannot keep the stop in {path}: {error}")

    def _recall(self) -> None:
        """Take the newest stop kept by this launch's holders (a holder restarted while the
        router is away starts stopped). A kept file that cannot be read may have held a stop:
        the holder starts stopped (fail safe), older than any stop or release given, so that
        the first one heard, or a running holder's answer, replaces it."""
        if self._kept is None or not self._kept.is_dir():
            return
        for path in sorted(self._kept.glob("*.json")):
            try:
                self.take(StopState.model_validate_json(path.read_text()))
            except (OSError, ValueError) as error:  # pydantic's ValidationError is a ValueError
                header = Header(stamp_ns=1, frame="", seq=0, source=UNREADABLE_SOURCE)
                why = str(error).splitlines()[0]
                reason = f"the stop kept in {path} unreadable ({why})"
                self.take(StopState(header=header, stopped=True, reason=reason))

    def _on_sample(self, sample: zenoh.Sample) -> None:
        """Zenoh thread: a stop or release given."""
        if sample.kind != zenoh.SampleKind.PUT:
            return
        key = str(sample.key_expr)
        try:
            state = codec.decode(sample.payload.to_bytes(), StopState, key)
        except codec.DecodeError as error:
            self.node.post(partial(self.node.warn, "rejected.control/stop", f"{key}: {error}"))
            return
        self.take(state)

    def _ask(self) -> None:
        """Take the newest stop the running components hold (a restart starts stopped). A
        session just opened learns the others' queryables a few ms later: it waits until one
        matches (up to ``ASK_WAIT_S``: none does when it is the first to start)."""
        querier = self.node.session.declare_querier(
            topics.status_selector(self.node.namespace), timeout=ASK_TIMEOUT_S
        )
        deadline = time.monotonic() + ASK_WAIT_S
        while not querier.matching_status.matching and time.monotonic() < deadline:
            time.sleep(0.002)
        for reply in querier.get():
            if reply.ok is None:
                continue
            try:
                key = str(reply.ok.key_expr)
                status = codec.decode(reply.ok.payload.to_bytes(), topics.STATUS_TYPE, key)
            except codec.DecodeError:
                continue  # a component of another version: it says nothing of the stop
            if status.stop is not None:
                self.take(status.stop)
        querier.undeclare()

    def _remind(self) -> None:
        """Timer: while stopped, put the stop again, for a holder that missed it (one that
        started in a partition, or whose question went unanswered); holders that have it
        ignore it."""
        if self.state.stopped:
            self._publisher.put(codec.encode(self.state))


def stop_state(stopped: bool, source: str, reason: str = "") -> StopState:
    """A stop (or a release) given now by ``source``, stamped on the wall clock."""
    header = Header(stamp_ns=time.time_ns(), frame="", seq=0, source=source)
    return StopState(header=header, stopped=stopped, reason=reason)


def release_refusal(profile: Profile, user: str, doing: str = "release the stop") -> str | None:
    """Why ``user`` may not release the stop, or None. A stop is anyone's who may open a
    session (who may see the robot: a profile should list no ``writers`` for ``control/stop``);
    a release lets the robot move again, so it is only for who may command it: who may put on
    ``control/goal`` and ``goal/request``. The router cannot tell a release from a stop (one
    key), so the tools that release obey this, as they obey the parameters' rules; so do the
    tools that teleoperate (``doing`` says what is refused)."""
    access = profile.zenoh.access
    if access is None:
        return None
    for topic in COMMAND_TOPICS:
        if not access.may_write(topic, user):
            return f"{user} may not {doing}: not a writer of {topic} (zenoh.access)"
    return None
