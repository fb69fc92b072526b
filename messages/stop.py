"""The namespace's emergency stop: latched or released, by whom, since when."""

from __future__ import annotations

from messages.base import Message
from messages.header import Header


class StopState(Message):
    """A stop (``stopped``) or a release of every motor of the namespace.

    ``header.source`` is who gave it (a tool's user, the control station's), ``header.stamp_ns``
    the giver's wall clock (ns since the epoch, whatever the profile's clock): a holder of the
    latch takes a state only when it is newer than the one it holds. ``reason`` is free text.
    """

    header: Header
    stopped: bool
    reason: str = ""
