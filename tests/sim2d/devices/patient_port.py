"""The SDK's port as the emulated servo chains' tests open it."""

from __future__ import annotations

from dynamixel_sdk import PortHandler


class PatientPort(PortHandler):
    """The SDK's own port, waiting up to a second for a status packet instead of the few
    milliseconds it sets per packet: the emulator's thread may be starved on a busy machine, and
    a test's verdict must not depend on that."""

    def setPacketTimeout(self, packet_length: int) -> None:  # noqa: N802 (the SDK's name)
        self.setPacketTimeoutMillis(1000.0)
