"""Recording, replay and report speed: record throughput, replay timing error, report time.

Run as ``python -m studies.bench.recording [--quick] [--json]``. This process opens a router on a
free loopback port and runs the real commands as processes:

1. ``parsimony record`` records while this process publishes, as fast as it can for 10 s,
   joint states, odometry and robot states in turn, (a) alone and (b) beside frames of
   ``deploy/sim.yaml``'s camera at its rate. The publishers block rather than drop, so only
   the recorder can lose a sample (and counts it, ``overflowed.<topic>``). Once its counters
   account for every message it is stopped with SIGINT and the file read back
   (``record.session_reader.info``): messages sent, read back, lost; per second until the last
   was written: messages, file MB and payload MB (the encoded messages sent).
2. ``parsimony replay FILE --rate R`` sends the recording of ``parsimony experiment pose``
   (lockstep) into the namespace; this process stamps each arrival (``time.monotonic_ns``),
   matches it to its recorded message by key and order, and gives the median and p99 of
   |replayed gap - recorded gap / R| between consecutive messages, all and camera frames, ms.
3. ``parsimony report``'s work (``load_session``, ``write_report``) on that recording repeated
   to span 60 s (``repeated_session``): median and each of 3 runs.

4. Memory (``studies.bench.long_sessions``): the recording repeated to span 30 and 120 s, and
   ``parsimony info``, ``report``, ``rerun`` and ``replay --rate 64`` run on each as processes:
   the peak resident memory of each (``ru_maxrss``, MB), and its ratio longest to shortest. A
   command that streams the file stays near 1 however long the session.

``--quick`` (under a minute): 1.5 s floods, the experiment cut at 3 s, one report of its
recording as it is, memory on spans of 5 and 20 s. Prints tables, or ``--json``; progress
goes to stderr.
"""

from __future__ import annotations

import argparse
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml
import zenoh
from pydantic import BaseModel

from analysis.report import write_report
from launch import query
from messages import codec, topics
from messages.base import default_joint_names
from messages.camera import CameraFrame, CameraIntrinsics
from messages.header import Header
from messages.joints import JointStates
from messages.odometry import BaseOdometry
from outputs.stdout import emit, json_text, result_only_stdout, table
from profiles.endpoints import free_port
from profiles.network import ZenohSettings
from profiles.profile import Profile, load_profile
from record.session_file import MESSAGE_ENCODING
from record.session_reader import info, read_session
from record.sessions import load_session
from sim2d.camera import ImageNoise, PlacedMarker, render
from sim2d.pinhole import ceiling_camera
from studies.bench.long_sessions import memory_use, repeated_session
from studies.bench.pubsub_workers import NAMESPACE, WAIT_S, message
from studies.bench.sim_experiments import percentile
from studies.experiment import PROFILES, SESSION_FILE, TIME_LIMIT_S, Options, run_experiment
from wbc.planar import planar_pose
from wbc.robot import MobileManipulator

SMALL = (topics.ARM_JOINT_STATES, topics.BASE_ODOMETRY, topics.ROBOT_STATE)
"""The small messages of the floods, sent in turn."""
FRAMES = 8
"""Distinct rendered camera frames the image load cycles through (noise differs)."""
SETTLE_S = 2.0
"""How long the recorder's counters, or the replay's arrivals, may stay still before we count."""
REPLAY_RATES = (1.0, 2.0)


@dataclass(frozen=True)
class Settings:
    """How much each part does: flood seconds, the experiment's time limit (simulated s; it
    stops sooner when it converges), report session seconds (None: the recording as it is) and
    report runs."""

    flood_s: float
    experiment_s: float
    report_s: float | None
    report_runs: int
    memory_spans_s: tuple[float, ...]


FULL = Settings(
    flood_s=10.0,
    experiment_s=TIME_LIMIT_S,
    report_s=60.0,
    report_runs=3,
    memory_spans_s=(30.0, 120.0),
)
QUICK = Settings(
    flood_s=1.5, experiment_s=3.0, report_s=None, report_runs=1, memory_spans_s=(5.0, 20.0)
)


def progress(text: str) -> None:
    print(f"[bench] {text}", file=sys.stderr, flush=True)


class Camera:
    """Camera frames of the simulation profile's scene camera (size, intrinsics, rate)."""

    def __init__(self, profile: Profile) -> None:
        scene = profile.scene
        self.settings = scene.camera
        reference = PlacedMarker(
            scene.reference.id, scene.reference.size_m, planar_pose(*scene.reference_pose)
        )
        camera, rng = ceiling_camera(scene.camera), np.random.default_rng(0)
        self.images = [
            render(camera, [reference], scene.dictionary_id, ImageNoise(), rng).tobytes()
            for _ in range(FRAMES)
        ]

    def frame(self, header: Header) -> CameraFrame:
        c = self.settings
        intrinsics = CameraIntrinsics(fx=c.fx, fy=c.fy, cx=c.cx, cy=c.cy)
        image = self.images[header.seq % FRAMES]
        return CameraFrame(
            header=header,
            encoding="mono8",
            width=c.width,
            height=c.height,
            data=image,
            intrinsics=intrinsics,
        )


def small_message(topic: topics.Topic, seq: int) -> BaseModel:
    """A joint state, odometry or robot state message stamped now."""
    if topic is topics.ROBOT_STATE:
        return message("state", seq, seq + 1, b"")[1]
    header = Header(stamp_ns=time.time_ns(), frame="bench", seq=seq, source="bench")
    if topic is topics.ARM_JOINT_STATES:
        return JointStates(
            header=header,
            names=default_joint_names(5),
            positions=(0.1, 0.2, 0.3, 0.4, 0.5),
            velocities=(0.0, 0.01, 0.02, 0.03, 0.04),
        )
    return BaseOdometry(
        header=header,
        left_encoder=seq,
        right_encoder=seq,
        left_distance=0.1,
        right_distance=0.1,
        x=0.5,
        y=0.2,
        phi=0.1,
        forward_velocity=0.1,
        angular_velocity=0.0,
    )


@dataclass
class Sent:
    """What a flood published: messages per topic name, payload bytes, seconds it took."""

    counts: Counter
    payload_bytes: int
    seconds: float
    started: float
    """``time.perf_counter`` at the first message."""


def flood(session: zenoh.Session, seconds: float, camera: Camera | None) -> Sent:
    """Small messages in turn as fast as this process can for ``seconds``, and a camera frame
    whenever one is due at the camera's rate (none without ``camera``)."""
    chosen = [*SMALL, topics.CAMERA_IMAGE] if camera is not None else list(SMALL)
    block = zenoh.CongestionControl.BLOCK
    publishers = {
        t.name: session.declare_publisher(t.key(NAMESPACE), congestion_control=block)
        for t in chosen
    }
    deadline = time.monotonic() + WAIT_S
    while not all(p.matching_status.matching for p in publishers.values()):
        if time.monotonic() > deadline:
            raise RuntimeError("the recorder does not subscribe to what the bench publishes")
        time.sleep(0.01)  # the recorder's subscriptions reach this session
    counts: Counter = Counter()
    payload_bytes, index = 0, 0
    started = next_frame = time.perf_counter()
    while (now := time.perf_counter()) < started + seconds:
        if camera is not None and now >= next_frame:
            seq = counts[topics.CAMERA_IMAGE.name]
            header = Header(stamp_ns=time.time_ns(), frame="camera", seq=seq, source="bench")
            topic, payload = topics.CAMERA_IMAGE, codec.encode(camera.frame(header))
            next_frame += 1.0 / camera.settings.rate_hz
        else:
            topic = SMALL[index % len(SMALL)]
            payload = codec.encode(small_message(topic, counts[topic.name]))
            index += 1
        publishers[topic.name].put(payload)
        counts[topic.name] += 1
        payload_bytes += len(payload)
    seconds = time.perf_counter() - started
    for publisher in publishers.values():
        publisher.undeclare()
    return Sent(counts, payload_bytes, seconds, started)


@contextmanager
def recording(profile: Path, path: Path, router: zenoh.Session) -> Iterator[subprocess.Popen]:
    """``parsimony record PROFILE -o PATH`` running, its recorder alive; stopped at the end by
    SIGINT to its process group (what Ctrl-C does), so the file gets its footer."""
    command = [sys.executable, "-m", "parsimony.cli", "record", str(profile), "-o", str(path)]
    process = subprocess.Popen(command, start_new_session=True)
    try:
        deadline = time.monotonic() + WAIT_S * 2
        while "recorder" not in query.live_components(router, NAMESPACE, 0.2):
            if process.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f"parsimony record did not come up (exit {process.poll()})")
        yield process
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGINT)
        try:
            process.wait(WAIT_S * 2)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()


def handled(counters: Mapping[str, int]) -> int:
    """Messages the recorder is done with: written, or dropped and counted."""
    dropped = ("overflowed.", "rejected.", "errors.")
    return counters.get("written", 0) + sum(v for k, v in counters.items() if k.startswith(dropped))


def wait_recorded(router: zenoh.Session, sent: Sent) -> tuple[float, dict[str, int]]:
    """Seconds from the first message sent until the recorder had handled every one (or its
    counters last moved, when some never come), and its counters then."""
    total, last, done_s = sum(sent.counts.values()), -1, 0.0
    still_since = time.monotonic()
    while True:
        status = query.statuses(router, NAMESPACE).get("recorder")
        counters = dict(status.counters) if status is not None else {}
        now = handled(counters)
        if now != last:
            last, done_s, still_since = now, time.perf_counter() - sent.started, time.monotonic()
        if now >= total or time.monotonic() - still_since > SETTLE_S:
            return done_s, counters
        time.sleep(0.05)  # polling the recorder's counters, not waiting for an event


def record_throughput(
    name: str,
    camera: Camera | None,
    settings: Settings,
    profile: Path,
    zenoh_settings: ZenohSettings,
    router: zenoh.Session,
    directory: Path,
) -> tuple[dict, dict[str, int]]:
    """One flood into a real recorder: the row of the table and the recorder's counters."""
    path = directory / f"{name.split()[0]}.mcap"
    progress(f"record: {name} for {settings.flood_s:g} s")
    with recording(profile, path, router) as process:
        with zenoh.open(zenoh_settings.component_config()) as session:
            sent = flood(session, settings.flood_s, camera)
            done_s, counters = wait_recorded(router, sent)  # closing sooner drops what is queued
    shown = info(path)
    recorded = sum(c["messages"] for c in shown["channels"] if c["encoding"] == MESSAGE_ENCODING)
    total = sum(sent.counts.values())
    row = {
        "load": name,
        "sent": total,
        "sent_hz": round(total / sent.seconds),
        "recorded": recorded,
        "lost": total - recorded,
        "overflowed": sum(v for k, v in counters.items() if k.startswith("overflowed.")),
        "recorded_hz": round(recorded / done_s),
        "file_MBps": round(shown["bytes"] / done_s / 1e6, 1),
        "payload_MBps": round(sent.payload_bytes / done_s / 1e6, 1),
        "file_MB": round(shown["bytes"] / 1e6, 1),
        "drain_s": round(done_s - sent.seconds, 2),
        "exit": process.returncode,
        "complete": shown["complete"],
    }
    return row, {k: v for k, v in sorted(counters.items()) if v}


def gap_errors_ms(
    recorded: Sequence[tuple[str, int]], arrivals: Mapping[str, Sequence[int]], rate: float
) -> list[float]:
    """|arrival gap - recorded gap / rate| in ms between each two consecutive recorded messages
    that both arrived. ``recorded``: (key, log time ns) in the order sent; ``arrivals``: per
    key, the arrival times (ns) in the order received. The i-th arrival on a key is the i-th
    recorded message on it (a key with fewer arrivals lost its last ones)."""
    seen: Counter = Counter()
    matched: list[tuple[int, int] | None] = []
    for key, log_ns in recorded:
        index, got = seen[key], arrivals.get(key, ())
        seen[key] += 1
        matched.append((log_ns, got[index]) if index < len(got) else None)
    return [
        abs((after[1] - before[1]) - (after[0] - before[0]) / rate) / 1e6
        for before, after in zip(matched, matched[1:], strict=False)
        if before is not None and after is not None
    ]


def replay_timing(session_file: Path, rate: float, profile: Path, router: zenoh.Session) -> dict:
    """``parsimony replay`` of ``session_file`` at ``rate`` into this process: its gap errors."""
    recorded = [
        (r.topic_name, r.log_time_ns)
        for r in read_session(session_file)
        if r.topic_name is not None
    ]
    command = [
        sys.executable,
        "-m",
        "parsimony.cli",
        "replay",
        str(session_file),
        "--profile",
        str(profile),
        "--rate",
        str(rate),
    ]
    progress(f"replay: {len(recorded)} messages at rate {rate:g}")
    arrivals: dict[str, list[int]] = {}  # per topic name, stamped on the receiving Zenoh thread

    def take(sample: zenoh.Sample) -> None:
        arrival = time.monotonic_ns()
        name = topics.topic_of_key(NAMESPACE, str(sample.key_expr)).name
        arrivals.setdefault(name, []).append(arrival)

    def received() -> int:
        return sum(len(times) for times in list(arrivals.values()))

    take_all = zenoh.handlers.Callback(take, indirect=False)
    subscriber = router.declare_subscriber(topics.namespace_selector(NAMESPACE), take_all)
    try:
        done = subprocess.run(command, timeout=WAIT_S * 20)
        if done.returncode != 0:
            raise RuntimeError(f"parsimony replay failed (exit {done.returncode})")
        count, still_since = -1, time.monotonic()
        while received() < len(recorded) and time.monotonic() - still_since < SETTLE_S:
            if received() != count:
                count, still_since = received(), time.monotonic()
            time.sleep(0.05)  # the last samples in flight
    finally:
        subscriber.undeclare()
    camera = topics.CAMERA_IMAGE.name
    every = gap_errors_ms(recorded, arrivals, rate)
    frames = gap_errors_ms([r for r in recorded if r[0] == camera], arrivals, rate)
    return {
        "rate": rate,
        "recorded": len(recorded),
        "received": received(),
        "all_median_ms": percentile_ms(every, 50),
        "all_p99_ms": percentile_ms(every, 99),
        "camera_median_ms": percentile_ms(frames, 50),
        "camera_p99_ms": percentile_ms(frames, 99),
    }


def percentile_ms(values_ms: list[float], q: float) -> float | None:
    """The q-th percentile of ms values, to the us."""
    return round(percentile([v * 1e3 for v in values_ms], q) / 1e3, 4) if values_ms else None


def report_time(session_file: Path, experiment: Path, runs: int, directory: Path) -> dict:
    """Seconds to load a session and write its figures and table (what ``parsimony report``
    does after its imports), ``runs`` times."""
    profile = load_profile(experiment / "profile.yaml")
    robot = MobileManipulator.from_yaml(profile.robot)
    shown = info(session_file)
    loads, draws = [], []
    for run in range(runs):
        started = time.perf_counter()
        session = load_session(session_file)
        loaded = time.perf_counter()
        write_report(
            [("lp", session)], robot, directory / f"report{run}", profile.scene.reference_pose
        )
        loads.append(round(loaded - started, 2))
        draws.append(round(time.perf_counter() - loaded, 2))
        del session
        progress(f"report run {run + 1}: load {loads[-1]} s, figures {draws[-1]} s")
    totals = [round(a + b, 2) for a, b in zip(loads, draws, strict=True)]
    return {
        "session_s": shown["duration_s"],
        "messages": shown["messages"],
        "file_MB": round(shown["bytes"] / 1e6, 1),
        "median_s": statistics.median(totals),
        "runs_s": totals,
        "load_s": loads,
        "figures_s": draws,
    }


def bench_profile(directory: Path, zenoh_settings: ZenohSettings) -> Path:
    """The profile ``parsimony record`` and ``replay`` are given: the bench's namespace and
    router (its one component is never run)."""
    profile = directory / "bench.yaml"
    component = {"name": "publisher", "module": "scripted_publisher", "role": "tool"}
    data = {
        "namespace": NAMESPACE,
        "components": [component],
        "zenoh": {"router": zenoh_settings.router, "mode": zenoh_settings.mode},
    }
    profile.write_text(yaml.safe_dump(data))
    return profile


def run(settings: Settings, directory: Path) -> dict:
    zenoh_settings = ZenohSettings(router=[f"tcp/127.0.0.1:{free_port()}"])
    profile = bench_profile(directory, zenoh_settings)
    camera = Camera(load_profile(PROFILES["lp"]))
    report: dict = {"record": [], "recorder_counters": {}, "replay": []}
    with zenoh.open(zenoh_settings.router_config()) as router:
        loads = (
            ("small messages", None),
            (f"images {camera.settings.rate_hz:g} Hz + small messages", camera),
        )
        for name, images in loads:
            row, counters = record_throughput(
                name, images, settings, profile, zenoh_settings, router, directory
            )
            report["record"].append(row)
            report["recorder_counters"][name] = counters
        experiment = directory / "experiment"
        progress("experiment pose --controller lp (lockstep), recorded")
        run_experiment(
            Options(
                name="pose", controller="lp", out=experiment, time_limit_s=settings.experiment_s
            )
        )
        recorded = experiment / SESSION_FILE
        for rate in REPLAY_RATES:
            report["replay"].append(replay_timing(recorded, rate, profile, router))
        report["memory"] = memory_use(recorded, settings.memory_spans_s, profile, directory)
    session = recorded
    if settings.report_s is not None:
        session = directory / "one_minute.mcap"
        progress(f"report: writing a {settings.report_s:g} s session from the recording")
        repeated_session(recorded, session, settings.report_s)
    report["report"] = report_time(session, experiment, settings.report_runs, directory)
    return report


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="a short run (under a minute)")
    parser.add_argument("--json", action="store_true", help="print JSON instead of tables")
    args = parser.parse_args(argv)
    started = time.monotonic()
    with tempfile.TemporaryDirectory() as directory:
        report = run(QUICK if args.quick else FULL, Path(directory))
    report = {
        "bench": "recording",
        "quick": args.quick,
        "cpus": os.cpu_count(),
        "duration_s": round(time.monotonic() - started, 1),
        **report,
    }
    if args.json:
        emit(json_text(report))
        return 0
    emit(table(report["record"]))
    for name, counters in report["recorder_counters"].items():
        emit(f"recorder counters ({name}): " + " ".join(f"{k}={v}" for k, v in counters.items()))
    emit("")
    emit(table(report["replay"]))
    emit("")
    emit(table([report["report"]]))
    emit("")
    emit("peak resident memory of each command, MB")
    emit(table(report["memory"]))
    return 0


if __name__ == "__main__":
    with result_only_stdout():  # what a library prints goes to stderr, not the result
        code = main()
    sys.exit(code)
