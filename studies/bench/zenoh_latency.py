"""Zenoh latency between processes on loopback, and the latency of a real controller loop.

Run as ``python -m studies.bench.zenoh_latency [--mode peer|client]``. This process opens a router;
a publisher process and a subscriber process connect to it as components do: in ``peer``
mode (the profile default) they link directly and the router only brokers, in ``client``
mode every sample goes through the router. Every
message is stamped ``time.time_ns()`` just before it is encoded and published; the
subscriber takes ``time.time_ns()`` once it has decoded it (one machine, one clock).

1. ``robot/state`` at 100 Hz: publish-to-receive latency, median and p99 (us).
2. ``camera/image`` (640x480 mono8) at 30, 100 and 300 Hz, then as fast as the publisher
   can: latency, rates sent and received, drops (frames sent but never received). The
   publishers are declared as components declare theirs (Zenoh's defaults: a frame that
   meets a full queue is dropped, the publisher never blocks).
3. The loop through an ``lp_controller`` process: states at 50 Hz from the publisher,
   ``arm/command`` at the subscriber. A command carries the stamp of the state it
   answers, so its age on arrival is the state-in to command-out latency.
4. A flood of ``world/obstacles``, as fast as the publisher can, into the same process
   (a newest-sample input: how many its handler decodes per second, how many were replaced
   before it could) and into a node with a queue input (every sample decoded, in order).
   Figures from the components' own counters.

Prints a table, or ``--json``. Runs in about 30 s.
"""

from __future__ import annotations

import argparse
import math
import multiprocessing as mp
import os
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml
import zenoh

from components.runtime import Node
from launch import query
from messages import topics
from messages.process import stop
from outputs.stdout import emit, json_text, result_only_stdout, table
from profiles.deploy_files import ROBOT_FILE
from profiles.endpoints import free_port
from profiles.network import ZenohSettings
from profiles.profile import load_profile
from studies.bench.pubsub_workers import (
    NAMESPACE,
    WAIT_S,
    Phase,
    publisher_main,
    subscriber_main,
)

SETTLE_S = 1.0
"""How long the subscriber may stay silent after the last publication before we count."""

TRANSPORT = (
    ("robot/state @100 Hz", topics.ROBOT_STATE, Phase("state", 500, 100.0)),
    ("camera/image 640x480 mono8 @30 Hz", topics.CAMERA_IMAGE, Phase("image", 300, 30.0)),
    ("camera/image 640x480 mono8 @100 Hz", topics.CAMERA_IMAGE, Phase("image", 300, 100.0)),
    ("camera/image 640x480 mono8 @300 Hz", topics.CAMERA_IMAGE, Phase("image", 300, 300.0)),
    ("camera/image 640x480 mono8 @max", topics.CAMERA_IMAGE, Phase("image", 300, 0.0)),
)
"""The transport measurements: name, topic, what the publisher sends."""


@dataclass
class Result:
    """One row of the report; latencies in us, rates in messages per second."""

    name: str
    sent: int
    received: int
    drops: int
    sent_hz: float
    recv_hz: float
    median_us: float | None
    p99_us: float | None
    solve_median_us: float | None = None
    optimal: int | None = None


class Bench:
    """The two worker processes and the phases they run."""

    def __init__(self, settings: ZenohSettings) -> None:
        context = mp.get_context("spawn")
        self.queues = {role: (context.Queue(), context.Queue()) for role in ("pub", "sub")}
        self.workers = [
            context.Process(target=target, args=(settings, *self.queues[role]), daemon=True)
            for role, target in (("sub", subscriber_main), ("pub", publisher_main))
        ]
        for worker in self.workers:
            worker.start()
        for role, (_, replies) in self.queues.items():
            if replies.get(timeout=WAIT_S * 2) != "ready":
                raise RuntimeError(f"the {role} process did not start")

    def close(self) -> None:
        for commands, _ in self.queues.values():
            commands.put(None)
        for worker in self.workers:
            worker.join(WAIT_S)

    def publish(self, phase: Phase) -> tuple[list[int], float]:
        commands, replies = self.queues["pub"]
        commands.put(phase)
        return replies.get(timeout=WAIT_S + phase.count / max(phase.rate_hz, 1.0))

    def collect(self, topic: topics.Topic, sent: list[int]) -> list[tuple[int, int, Any]]:
        """What the subscriber received of ``sent`` (by stamp), once it has all or settles."""
        commands, replies = self.queues["sub"]
        wanted, records = set(sent), []
        deadline = time.monotonic() + SETTLE_S
        while time.monotonic() < deadline:
            commands.put(topic.name)
            fresh = [r for r in replies.get(timeout=WAIT_S) if r[0] in wanted]
            records += fresh
            if fresh:
                deadline = time.monotonic() + SETTLE_S
            if len({r[0] for r in records}) == len(wanted):
                break
            time.sleep(0.05)
        return records

    def measure(self, name: str, topic: topics.Topic, phase: Phase) -> Result:
        sent, duration_s = self.publish(phase)
        return summary(name, sent, duration_s, self.collect(topic, sent))


def summary(
    name: str, sent: list[int], duration_s: float, records: list, diagnostics: list = ()
) -> Result:
    """Latency (arrival - stamp) of ``records``; solve time and optimal steps of ``diagnostics``."""
    latencies = np.array([(arrival - stamp) / 1e3 for stamp, arrival, _ in records])
    received = len({stamp for stamp, _, _ in records})
    solve = [note[0] for _, _, note in diagnostics]
    return Result(
        name=name,
        sent=len(sent),
        received=received,
        drops=len(sent) - received,
        sent_hz=rate(len(sent), duration_s * 1e9),
        recv_hz=rate(received, arrival_span(records)),
        median_us=round(float(np.median(latencies)), 1) if received else None,
        p99_us=round(float(np.percentile(latencies, 99)), 1) if received else None,
        solve_median_us=round(float(np.median(solve)), 1) if solve else None,
        optimal=sum(note[1] == "optimal" for _, _, note in diagnostics) if diagnostics else None,
    )


def controller_loop(
    bench: Bench, settings: ZenohSettings, router: zenoh.Session
) -> tuple[Result, dict[str, int]]:
    """States at 50 Hz through a real lp_controller process: the latency of its arm
    commands, its solve times, and its non-zero counters (a state that arrives while the
    previous one waits replaces it: ``overwritten.robot/state``)."""
    with tempfile.TemporaryDirectory() as directory:
        profile = Path(directory) / "bench.yaml"
        component = {"name": "controller", "module": "lp_controller", "role": "controller"}
        sink = {"name": "sink", "module": "scripted_publisher", "role": "tool"}  # never run
        data = {"namespace": NAMESPACE, "zenoh": {"router": settings.router, "mode": settings.mode}}
        data |= {"robot": str(ROBOT_FILE), "components": [component, sink]}
        profile.write_text(yaml.safe_dump(data))
        command = [sys.executable, "-m", "components.lp_controller", "--profile", str(profile)]
        process = subprocess.Popen([*command, "--name", "controller", "--log-level", "WARNING"])
        sink_node = Node(load_profile(profile), "sink")
        try:
            sink_node.__enter__()
            arrivals: list[int] = []
            sink_node.subscribe(
                topics.WORLD_OBSTACLES,
                lambda _: arrivals.append(time.perf_counter_ns()),
                FLOOD.count,
            )
            sink_node.start()
            deadline = time.monotonic() + WAIT_S
            while "controller" not in query.live_components(router, NAMESPACE, 0.2):
                if time.monotonic() > deadline or process.poll() is not None:
                    raise RuntimeError("the lp_controller process did not come up")
            bench.publish(Phase("goal", 1, 0.0))
            while not goal_taken(router):
                if time.monotonic() > deadline:
                    raise RuntimeError("the controller did not take the goal")
            sent, duration_s = bench.publish(Phase("state", 400, 50.0))
            arm = bench.collect(topics.ARM_COMMAND, sent)
            diagnostics = bench.collect(topics.CONTROL_DIAGNOSTICS, sent)
            counters = query.statuses(router, NAMESPACE)["controller"].counters
            flood = decode_rate(bench, router, sink_node, arrivals)
        finally:
            sink_node.close()
            stop(process, signal.SIGTERM, WAIT_S)
    name = "state -> lp_controller -> arm/command @50 Hz"
    counters = {name: count for name, count in counters.items() if count}
    return summary(name, sent, duration_s, arm, diagnostics), counters, flood


FLOOD = Phase("obstacles", 20_000, 0.0)
"""The flood of ``decode_rate``."""


def decode_rate(
    bench: Bench, router: zenoh.Session, sink: Node, decoded_ns: list[int]
) -> dict[str, dict[str, int]]:
    """Flood ``world/obstacles`` into the controller (newest-sample input) and into ``sink``,
    a node of this process with a queue input as large as the flood whose handler appends
    to ``decoded_ns`` the time it got each message. Wait until the counters of both account
    for every message sent (decoded, replaced or refused).

    Decoded per second: for the queue input, from its first decoded message to its last;
    for the controller, whose newest-sample input decodes only while the flood lasts, over
    the flood's duration."""
    topic = topics.WORLD_OBSTACLES.name
    kinds = ("received", "overwritten", "overflowed", "rejected")

    def counts() -> dict[str, dict[str, int]]:
        controller = query.statuses(router, NAMESPACE)["controller"].counters
        return {
            name: {kind: counters.get(f"{kind}.{topic}", 0) for kind in kinds}
            for name, counters in (("lp_controller", controller), ("queue input", sink.counters))
        }

    before, done_s = counts(), {}
    decoded_ns.clear()
    started = time.monotonic()
    sent, sent_s = bench.publish(FLOOD)
    deadline = time.monotonic() + WAIT_S
    while True:
        now, elapsed_s = counts(), time.monotonic() - started
        handled = {
            name: {kind: now[name][kind] - before[name][kind] for kind in kinds} for name in now
        }
        for name, figures in handled.items():
            if name not in done_s and sum(figures.values()) >= len(sent):
                done_s[name] = elapsed_s
        if len(done_s) == len(now) or time.monotonic() > deadline:
            break
        time.sleep(0.01)  # polling the counters, not waiting for an event
    report = {}
    for name, figures in handled.items():
        lost = len(sent) - sum(figures.values())
        report[name] = {"sent": len(sent), "sent_hz": round(len(sent) / sent_s), **figures}
        report[name]["lost"] = lost
    span_s = (decoded_ns[-1] - decoded_ns[0]) / 1e9 if len(decoded_ns) > 1 else math.inf
    report["queue input"]["decoded_hz"] = round((len(decoded_ns) - 1) / span_s)
    report["lp_controller"]["decoded_hz"] = round(report["lp_controller"]["received"] / sent_s)
    return report


def rate(count: int, span_ns: float) -> float:
    """Messages per second of ``count`` messages spread over ``span_ns``."""
    return round((count - 1) * 1e9 / span_ns, 1) if count > 1 and span_ns > 0 else 0.0


def arrival_span(records: list) -> int:
    """Nanoseconds from the first arrival to the last."""
    arrivals = [arrival for _, arrival, _ in records]
    return max(arrivals) - min(arrivals) if arrivals else 0


def goal_taken(router: zenoh.Session) -> bool:
    status = query.statuses(router, NAMESPACE).get("controller")
    return status is not None and status.counters["received.control/goal"] > 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mode", choices=("peer", "client"), default=ZenohSettings().mode)
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    args = parser.parse_args(argv)
    settings = ZenohSettings(router=[f"tcp/127.0.0.1:{free_port()}"], mode=args.mode)
    started = time.monotonic()
    with zenoh.open(settings.router_config()) as router:
        bench = Bench(settings)
        try:
            results = [bench.measure(*measurement) for measurement in TRANSPORT]
            loop, counters, flood = controller_loop(bench, settings, router)
            results.append(loop)
        finally:
            bench.close()
    report = {"bench": "zenoh_latency", "mode": settings.mode, "cpus": os.cpu_count()}
    report |= {"duration_s": round(time.monotonic() - started, 1)}
    report |= {"results": [asdict(r) for r in results], "controller_counters": counters}
    report |= {"flood": flood}
    if args.json:
        emit(json_text(report))
    else:
        emit(table([asdict(r) for r in results]))
        emit("lp_controller counters: " + " ".join(f"{k}={v}" for k, v in sorted(counters.items())))
        for name, figures in flood.items():
            emit(
                f"world/obstacles flood into the {name}: "
                + " ".join(f"{k}={v}" for k, v in figures.items())
            )
    return 0


if __name__ == "__main__":
    with result_only_stdout():  # what a library prints goes to stderr, not the result
        code = main()
    sys.exit(code)
