"""The emergency stop in the control station (``view.control_station``): a boolean among
Foxglove's parameters, true while the namespace is stopped; set true to stop (whoever the
view's user), false to release (only a user who may command the robot:
``components.stop_latch.release_refusal``)."""

from __future__ import annotations

from typing import Any

import zenoh
from foxglove import Parameter

from components.stop_latch import release_refusal, stop_state
from launch.query import statuses
from messages import topics
from messages.stop import StopState
from profiles.profile import Profile
from view.client_limits import ECHO_CHARS, cut

STOP_PARAMETER = topics.CONTROL_STOP.name
"""The stop control's name in Foxglove's Parameters panel."""


def stop_parameters(session: zenoh.Session, namespace: str) -> list[Parameter]:
    """``STOP_PARAMETER``, whether a running component holds a stop; none when no running
    component holds the latch."""
    held = [s.stop for s in statuses(session, namespace).values() if s.stop is not None]
    return [Parameter(STOP_PARAMETER, value=any(s.stopped for s in held))] if held else []


def stop_given(profile: Profile, user: str, client: int, value: Any) -> StopState | str:
    """The stop (``value`` true) or release (false) the view's ``client`` gives as ``user``,
    or why it is refused."""
    if not isinstance(value, bool):
        return f"{STOP_PARAMETER} = {cut(repr(value), ECHO_CHARS)} refused: true or false"
    refusal = None if value else release_refusal(profile, user)
    return refusal or stop_state(value, user, f"the view's client {client}")
