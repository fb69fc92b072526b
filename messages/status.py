"""What a running component reports about itself."""

from __future__ import annotations

from pydantic import Field

from messages.base import Count, Message
from messages.header import Header
from messages.process import ParamValue
from messages.stop import StopState


class ComponentStatus(Message):
    """A component's periodic self-report.

    ``name`` is the instance name from the profile, ``module`` the Python module
    it runs, ``state`` its life-cycle state, ``pid`` its process id,
    ``counters`` monotonic event counts (messages in, out, dropped...) and
    ``parameters`` its current tunable parameters; ``stop`` the emergency stop it holds (a
    component that obeys the stop: ``components.stop_latch``), else None.
    """

    header: Header
    name: str
    module: str
    state: str
    pid: Count
    counters: dict[str, Count] = Field(default_factory=dict)
    parameters: dict[str, ParamValue] = Field(default_factory=dict)
    stop: StopState | None = None
