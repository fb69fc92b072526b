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
import statistics
import subprocess
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import yaml
import zenoh

from analysis.report import write_report
from messages import topics
from outputs.stdout import emit, json_text, result_only_stdout, table
from profiles.endpoints import free_port
from profiles.network import ZenohSettings
from profiles.profile import load_profile
from record.session_reader import info, read_session
from record.sessions import load_session
from studies.bench.long_sessions import memory_use, repeated_session
from studies.bench.pubsub_workers import NAMESPACE, WAIT_S
from studies.bench.record_throughput import SETTLE_S, Camera, progress, record_throughput
from studies.bench.sim_experiments import percentile
from studies.experiment import PROFILES, SESSION_FILE, TIME_LIMIT_S, Options, run_experiment
from wbc.robot import MobileManipulator

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
                name, images, settings.flood_s, profile, zenoh_settings, router, directory
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
