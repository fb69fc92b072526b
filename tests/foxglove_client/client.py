"""For tests: Foxglove's own WebSocket client (``@foxglove/ws-protocol`` run by node,
``client.mjs`` beside this file) as a process a test drives, and what it hears.

``make test`` installs the package from ``package-lock.json`` (``make foxglove-client``)."""

from __future__ import annotations

import base64
import contextlib
import functools
import json
import shutil
import signal
import subprocess
import sys
import threading
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from google.protobuf import descriptor_pb2, descriptor_pool, json_format, message_factory

from profiles.endpoints import free_port

HERE = Path(__file__).resolve().parent
SCRIPT = HERE / "client.mjs"
INSTALLED = HERE / "node_modules" / "@foxglove" / "ws-protocol"
DEADLINE_S = 60.0
"""Generous limit for what a loaded machine's processes should have said long before."""


def missing() -> str:
    """Why the client cannot run here, or empty."""
    if shutil.which("node") is None:
        return "node is not installed"
    if not INSTALLED.is_dir():
        return f"{INSTALLED} is not installed: run `make foxglove-client`"
    return ""


@dataclass
class RunningView:
    """A ``parsimony view`` process, where it listens, and the line that says so (and whether
    clients may publish); once it stopped, the rest of its output."""

    process: subprocess.Popen
    address: str
    live_line: str
    out: str = ""
    err: str = ""


@contextlib.contextmanager
def running_view(
    profile: Path, *flags: str, env: dict[str, str] | None = None, timeout_s: float = DEADLINE_S
) -> Iterator[RunningView]:
    """``parsimony view PROFILE --port P FLAGS`` on a free port of 127.0.0.1, once it has said
    that it is live (or has ended: ``live_line`` is then its last line); stopped with SIGTERM
    at the end, its output and exit status kept (``out``, ``err``, ``process.returncode``)."""
    port = free_port()
    process = subprocess.Popen(
        [sys.executable, "-m", "parsimony.cli", "view", str(profile), "--port", str(port), *flags],
        text=True,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert process.stderr is not None
    line = said = process.stderr.readline()
    while said and " live at " not in line:
        said = process.stderr.readline()
        line = said or line
    view = RunningView(process, f"ws://127.0.0.1:{port}", line)
    try:
        yield view
    finally:
        process.send_signal(signal.SIGTERM)
        view.out, view.err = process.communicate(timeout=timeout_s)


class FoxgloveClient:
    """``client.mjs`` connected to ``address``; ``events`` holds what it heard, in order. A
    context manager: leaving closes it. ``count``: messages are counted, not heard one by one
    (``counts``)."""

    def __init__(self, address: str, count: bool = False) -> None:
        command = ["node", str(SCRIPT), address, *(["--count"] if count else [])]
        self.process = subprocess.Popen(
            command, cwd=HERE, text=True, stdin=subprocess.PIPE, stdout=subprocess.PIPE
        )
        self.events: list[dict[str, Any]] = []
        self._changed = threading.Condition()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def __enter__(self) -> FoxgloveClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            with self._changed:
                self.events.append(json.loads(line))
                self._changed.notify_all()
        with self._changed:
            self.events.append({"event": "exited"})
            self._changed.notify_all()

    def send(self, op: str, **fields: Any) -> None:
        assert self.process.stdin is not None
        self.process.stdin.write(json.dumps({"op": op, **fields}) + "\n")
        self.process.stdin.flush()

    def wait_for(
        self, found: Callable[[dict[str, Any]], bool], what: str, start: int = 0
    ) -> dict[str, Any]:
        """The first event from index ``start`` on that ``found`` accepts; fails, saying
        ``what`` was awaited, if the client exits or ``DEADLINE_S`` passes first."""

        def first() -> dict[str, Any] | None:
            for event in self.events[start:]:
                if found(event):
                    return event
                if event["event"] == "exited":
                    raise AssertionError(f"the client exited before {what}: {self.events[-5:]}")
            return None

        with self._changed:
            event = self._changed.wait_for(first, DEADLINE_S)
        assert event is not None, f"no {what} within {DEADLINE_S} s"
        return event

    def server_info(self) -> dict[str, Any]:
        return self.wait_for(lambda e: e["event"] == "serverInfo", "the server's info")

    def channels(self) -> dict[str, dict[str, Any]]:
        """Every channel advertised so far, by topic."""
        with self._changed:
            return {
                c["topic"]: c
                for e in self.events
                if e["event"] == "advertise"
                for c in e["channels"]
            }

    def messages(self, topic: str) -> list[tuple[int, bytes]]:
        """(log time, payload) of every message heard on ``topic`` so far (one still in flight
        when its subscription ended names no topic: the client no longer knows it)."""
        with self._changed:
            return [
                (int(e["logTime"]), base64.b64decode(e["data"]))
                for e in self.events
                if e["event"] == "message" and e.get("topic") == topic
            ]

    def message(
        self, topic: str, found: Callable[[int, bytes], bool] = lambda t, d: True, what: str = ""
    ) -> tuple[int, bytes]:
        """The first message on ``topic`` that ``found(log_time, payload)`` accepts."""
        event = self.wait_for(
            lambda e: (
                e["event"] == "message"
                and e.get("topic") == topic
                and found(int(e["logTime"]), base64.b64decode(e["data"]))
            ),
            what or f"a message on {topic}",
        )
        return int(event["logTime"]), base64.b64decode(event["data"])

    def counts(self) -> dict[str, tuple[int, int, int]]:
        """Per topic, the messages, bytes and last log time counted so far (``count``)."""
        start = len(self.events)
        self.send("counts")
        event = self.wait_for(lambda e: e["event"] == "counts", "the counts", start)
        return {topic: (n, size, int(last)) for topic, (n, size, last) in event["counts"].items()}

    def close(self) -> None:
        if self.process.poll() is None:
            self.send("close")
            try:
                self.process.wait(DEADLINE_S)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self._reader.join(DEADLINE_S)


@functools.cache
def _message_class(schema_name: str, schema_base64: str) -> type:
    pool = descriptor_pool.DescriptorPool()
    files = descriptor_pb2.FileDescriptorSet.FromString(base64.b64decode(schema_base64))
    for file in files.file:
        pool.Add(file)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(schema_name))


def decode(channel: dict[str, Any], payload: bytes) -> dict[str, Any]:
    """A message as a dict, read by Google's protobuf with nothing but the schema its channel
    advertised (protobuf channels) or as JSON (the project's channels)."""
    if channel["encoding"] == "json":
        return json.loads(payload)
    assert (channel["encoding"], channel["schemaEncoding"]) == ("protobuf", "protobuf"), channel
    message = _message_class(channel["schemaName"], channel["schema"]).FromString(payload)
    return json_format.MessageToDict(message, preserving_proto_field_name=True)
