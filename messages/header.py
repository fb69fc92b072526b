"""The header every message carries."""

from __future__ import annotations

from messages.base import Count, Message


class Header(Message):
    """When, where and by whom a message was made.

    ``stamp_ns`` is nanoseconds on the clock of the profile (simulated or wall),
    ``frame`` the coordinate frame the data is expressed in, ``seq`` a counter
    the publisher increments per message, and ``source`` the publishing
    component's name.
    """

    stamp_ns: Count
    frame: str
    seq: Count
    source: str
