"""What the live view's tests and the replay's share: a robot state of a given sequence number, a
profile on a free loopback port, a command run as a shell's background job, a process's stderr
read as it comes, and a WebSocket client that watches channels as the Foxglove app does
(subprotocol ``foxglove.sdk.v1``)."""

from __future__ import annotations

import asyncio
import json
import signal
import struct
import subprocess
import sys
import threading
from pathlib import Path
from typing import Any

import yaml
from websockets.asyncio.client import connect
from websockets.typing import Subprotocol

from messages.header import Header
from messages.state import RobotState
from profiles.endpoints import free_port

NAMESPACE = "live"
DEADLINE_S = 60.0
"""Generous limit for anything that waits on a process of a loaded machine."""
FIRST_STAMP_NS = 1_700_000_000_000_000_000
MESSAGE_DATA = 0x01
"""The opcode of a binary message-data frame: then u32 subscription id, u64 log time."""
UNKNOWN_CHANNEL = "Unknown channel ID: "
"""How the server's status message starts when it refuses a subscription."""
WATCHED_MESSAGES = 30
"""How many messages the client reads before it leaves: while it reads the image, every payload
on its key, the ones that are not messages too, reaches the view's decoder (a key no client
reads is not decoded)."""


def header(seq: int) -> Header:
    return Header(stamp_ns=FIRST_STAMP_NS + seq * 50_000_000, frame="world", seq=seq, source="test")


def state(seq: int) -> RobotState:
    return RobotState(
        header=header(seq),
        base_pose=(0.5 + 0.01 * seq, -0.25, 0.3),
        arm_joints=(0.1, -0.2, 0.3, -0.4, 0.5),
        end_effector=(1.0, 0.0, 0.0, 0.0, 0.0, 0.2, 0.1, 0.25),
        valid=True,
        age_s=0.0,
    )


def write_profile(directory: Path) -> Path:
    """A profile of the namespace, its router on a free loopback port."""
    profile = directory / "live.yaml"
    profile.write_text(
        yaml.safe_dump(
            {
                "namespace": NAMESPACE,
                "zenoh": {"router": [f"tcp/127.0.0.1:{free_port()}"]},
                "components": [{"name": "x", "module": "scripted_publisher", "role": "tool"}],
            }
        )
    )
    return profile


def background_job(*words: str) -> subprocess.Popen[str]:
    """``parsimony WORDS`` started as a shell without job control starts ``cmd &`` (a suite run
    in the background, ``nohup``): SIGINT and SIGQUIT ignored, which the command inherits; its
    stderr piped."""
    return subprocess.Popen(
        ["sh", "-c", 'trap "" INT QUIT; exec "$@"', "sh"]
        + [sys.executable, "-m", "parsimony.cli", *words],
        stdin=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )


def stopped_by(process: subprocess.Popen[str], signum: signal.Signals) -> int:
    """``process``'s exit code once ``signum`` stopped it; killed, and the test failed, if it
    did not within ``DEADLINE_S``."""
    process.send_signal(signum)
    try:
        return process.wait(DEADLINE_S)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
        stuck = f"{process.args} did not stop within {DEADLINE_S} s of {signum.name}"
        raise AssertionError(stuck) from None


class StderrLines:
    """The lines a process writes to stderr, read as they come."""

    def __init__(self, process: subprocess.Popen[str]) -> None:
        self.lines: list[str] = []
        self._changed = threading.Condition()
        self._thread = threading.Thread(target=self._read, args=(process,))
        self._thread.start()

    def _read(self, process: subprocess.Popen[str]) -> None:
        for line in process.stderr:
            with self._changed:
                self.lines.append(line)
                self._changed.notify_all()

    def wait_for(self, text: str) -> str:
        """The first line holding ``text``, waiting for it up to ``DEADLINE_S``."""
        with self._changed:
            found = self._changed.wait_for(
                lambda: next((line for line in self.lines if text in line), None), DEADLINE_S
            )
        assert found, f"no {text!r} on stderr within {DEADLINE_S} s: {self.lines}"
        return found

    def all(self) -> str:
        """Everything, once the process has closed its stderr."""
        self._thread.join(DEADLINE_S)
        return "".join(self.lines)


async def watch(address: str, wanted: set[str]) -> tuple[dict, dict[str, tuple[int, bytes]]]:
    """As the Foxglove app: read serverInfo and the advertisements until the ``wanted``
    channels are there, subscribe to them, read ``WATCHED_MESSAGES`` at least, and return them
    by topic with the first (log time, payload) each sends."""
    async with (
        asyncio.timeout(DEADLINE_S),
        connect(address, subprotocols=[Subprotocol("foxglove.sdk.v1")], max_size=None) as client,
    ):
        assert client.subprotocol == "foxglove.sdk.v1"
        server_info = json.loads(await client.recv())
        assert server_info["op"] == "serverInfo", server_info
        channels: dict[str, dict[str, Any]] = {}
        while not wanted <= set(channels):
            message = json.loads(await client.recv())
            if message["op"] == "advertise":
                channels |= {channel["topic"]: channel for channel in message["channels"]}
        topic_of = dict(enumerate(sorted(wanted), start=1))

        async def subscribe(chosen: dict[int, str]) -> None:
            await client.send(
                json.dumps(
                    {
                        "op": "subscribe",
                        "subscriptions": [
                            {"id": sid, "channelId": channels[topic]["id"]}
                            for sid, topic in chosen.items()
                        ],
                    }
                )
            )

        await subscribe(topic_of)
        first: dict[str, tuple[int, bytes]] = {}
        received = 0
        while set(first) != wanted or received < WATCHED_MESSAGES:
            message = await client.recv()
            if isinstance(message, bytes) and message[0] == MESSAGE_DATA:
                subscription, log_time = struct.unpack_from("<IQ", message, 1)
                first.setdefault(topic_of[subscription], (log_time, message[13:]))
                received += 1
            elif isinstance(message, str) and UNKNOWN_CHANNEL in message:
                # foxglove-sdk 0.30 sends an advertisement before it records the channel as
                # advertised to this client: a subscription that follows at once can be refused.
                unknown = int(json.loads(message)["message"].removeprefix(UNKNOWN_CHANNEL))
                await subscribe(
                    {
                        sid: topic
                        for sid, topic in topic_of.items()
                        if channels[topic]["id"] == unknown
                    }
                )
        return channels, first
