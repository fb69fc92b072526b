"""What `parsimony view` costs the loop, and what it holds for a client that reads nothing.

Run as ``python -m studies.bench.live_view [--runs N] [--json]`` (node and ``make foxglove-client``:
the client is Foxglove's own, ``tests/foxglove_client``). One system of
deploy/sim_supervised.yaml in lockstep (the simulator steps as fast as the loop answers), with
a recorder, on the 6.2.1 set-up, on a namespace and port of its own. ``--runs`` rounds of three
windows of ``WINDOW_S`` host seconds: without a view, then twice with `parsimony view` and one
client counting what it receives as fast as it can read: one that reads what Foxglove reads
with the layout (every view, the diagnostics, the supervisor's status), one that reads every
channel. Per window, the loop's real-time factor (simulated seconds from sim/clock stamps, per
host second) and its CPU seconds per simulated second (its components' own count); in the
view's windows, the view's CPU (its process's user and system time, per host second and per
simulated second: the second is the one that does not move with the machine's other load) and
its handler's median and p99 per sample (the view's own count, ``--json``).
Then the view's resident memory while one client (of the layout) reads nothing for
``STALL_S`` (its socket paused), and how many frames of the robot's states the view dropped
for that client rather than queue them. Last, the recording's bytes per simulated second,
rewritten as it is and without what this view adds (the robot's links and model, the plan, the
annotations, the markers' corners).
"""

from __future__ import annotations

import contextlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import yaml
import zenoh

from launch import query
from launch.stop import cpu_seconds
from messages import codec, topics
from messages.markers import MarkerDetections
from messages.supervisor import SupervisorStatus
from outputs.stdout import table
from profiles.deploy_files import DEPLOY
from profiles.endpoints import free_port
from profiles.profile import load_profile
from record.session_file import SessionWriter, entries
from record.session_reader import info, read_session
from scenes.foxglove_views import ANNOTATIONS_SUFFIX, SCENE_SUFFIX, Viewer
from studies.bench.figures import run_bench
from studies.launched import connect, launched, wait_alive, wait_reached
from tests.foxglove_client.client import FoxgloveClient, missing, running_view
from wbc.robot import MobileManipulator

WINDOW_S = 20.0
"""Host seconds of each measured window."""
WARM_S = 3.0
"""Host seconds between starting a view (or not) and measuring."""
STALL_S = 20.0
"""How long the stalled client reads nothing."""
SAMPLE_S = 0.5


def lockstep_profile(
    directory: Path, base: Path = DEPLOY / "sim_supervised.yaml", name: str = "liveview"
) -> Path:
    """``base`` on a namespace and port of its own, in lockstep (paused until everything is
    up), with a recorder writing ``directory``/session.mcap: the system a view watches."""
    path = directory / f"{name}.yaml"
    path.write_text(
        yaml.safe_dump(
            {
                "extends": str(base),
                "namespace": f"{name}{os.getpid()}",
                "zenoh": {"router": [f"tcp/127.0.0.1:{free_port()}"]},
                "startup_timeout_s": 60.0,
                "components": [
                    {
                        "name": "simulator",
                        "params": {"lockstep": True, "real_time_factor": 0.0, "paused": True},
                    },
                    {
                        "name": "recorder",
                        "module": "recorder",
                        "role": "recorder",
                        "restart": {"policy": "never"},
                        "params": {"path": str(directory / "session.mcap")},
                    },
                ],
            }
        )
    )
    return path


class Counter:
    """The latest sim/clock stamp and the robot states published, as they come."""

    def __init__(self, session: zenoh.Session, namespace: str) -> None:
        self.clock_ns, self.states = 0, 0
        self._lock = threading.Lock()
        self._subscribers = [
            session.declare_subscriber(topics.SIM_CLOCK.key(namespace), self._on_clock),
            session.declare_subscriber(topics.ROBOT_STATE.key(namespace), self._on_state),
        ]

    def _on_clock(self, sample: zenoh.Sample) -> None:
        stamp = codec.decode(sample.payload.to_bytes(), topics.SIM_CLOCK.type).stamp_ns
        with self._lock:
            self.clock_ns = max(self.clock_ns, stamp)

    def _on_state(self, sample: zenoh.Sample) -> None:
        with self._lock:
            self.states += 1

    def read(self) -> tuple[int, int]:
        with self._lock:
            return self.clock_ns, self.states


def rss_mb(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise RuntimeError(f"no VmRSS for {pid}")


LAYOUT_CLIENT = {
    "schemaPrefix": "foxglove.",
    "topics": [topics.CONTROL_DIAGNOSTICS.name, topics.SUPERVISOR_STATUS.name],
}
"""What Foxglove reads with the layout of `parsimony layout`: every view (the 3-D panel reads
every transform, the scenes, the image and its annotations) and the diagnostics and the
supervisor's status (plots, messages); topic names are made keys in ``viewing``."""
EVERY_CHANNEL: dict = {}


@contextlib.contextmanager
def viewing(
    profile_path: Path, namespace: str, reads: dict
) -> Iterator[tuple[subprocess.Popen, FoxgloveClient, dict]]:
    """A `parsimony view` and one counting client that reads the channels ``reads`` says
    (``LAYOUT_CLIENT``, ``EVERY_CHANNEL``); at the end the view's own summary fills the
    dict."""
    summary: dict = {}
    with running_view(profile_path, "--json") as view:
        if "live at" not in view.live_line:
            raise RuntimeError(f"the view did not start: {view.live_line}")
        with FoxgloveClient(view.address, count=True) as client:
            client.server_info()
            keys = [f"{namespace}/{topic}" for topic in reads.get("topics", ())]
            client.send("subscribeAll", **{**reads, "topics": keys})
            yield view.process, client, summary
    summary.update(json.loads(view.out) if view.out.strip() else {})


def loop_cpu_s(session: zenoh.Session, namespace: str) -> float:
    """The CPU seconds every component of the system has used so far."""
    return sum(s.counters["cpu_ms"] for s in query.statuses(session, namespace).values()) / 1e3


def window(
    counter: Counter, session: zenoh.Session, namespace: str, pid: int | None = None
) -> dict:
    """Over ``WINDOW_S``: the loop's real-time factor and CPU seconds per simulated second (its
    components'), and the view's CPU share of a core and CPU seconds per simulated second if
    ``pid``."""
    time.sleep(WARM_S)
    (clock0, _), wall0 = counter.read(), time.monotonic()
    loop0, cpu0 = loop_cpu_s(session, namespace), cpu_seconds(pid) if pid else 0.0
    time.sleep(WINDOW_S)
    (clock1, _), wall1 = counter.read(), time.monotonic()
    loop1, cpu1 = loop_cpu_s(session, namespace), cpu_seconds(pid) if pid else 0.0
    sim_s = (clock1 - clock0) / 1e9
    found = {
        "rtf": round(sim_s / (wall1 - wall0), 3),
        "loop_cpu_per_sim_s": round((loop1 - loop0) / sim_s, 3),
    }
    if pid:
        found["view_cpu_share"] = round((cpu1 - cpu0) / (wall1 - wall0), 3)
        found["view_cpu_per_sim_s"] = round((cpu1 - cpu0) / sim_s, 3)
    return found


def stalled_client(profile_path: Path, counter: Counter, namespace: str) -> dict:
    """The view's memory while its one client reads nothing for ``STALL_S``, and the states it
    dropped for it rather than queue them."""
    state_key = topics.ROBOT_STATE.key(namespace) + "/foxglove"
    with viewing(profile_path, namespace, LAYOUT_CLIENT) as (view, client, _):
        time.sleep(WARM_S)
        before = rss_mb(view.pid)
        received_before = client.counts().get(state_key, (0, 0, 0))[0]
        _, published_before = counter.read()
        client.send("pause")
        samples = []
        end = time.monotonic() + STALL_S
        while time.monotonic() < end:
            time.sleep(SAMPLE_S)
            samples.append(rss_mb(view.pid))
        client.send("resume")
        _, published_after = counter.read()
        time.sleep(WARM_S)
        received = client.counts().get(state_key, (0, 0, 0))[0] - received_before
    published = published_after - published_before
    return {
        "rss_mb_before": round(before, 1),
        "rss_mb_max": round(max(samples), 1),
        "rss_mb_end": round(samples[-1], 1),
        "states_published": published,
        "states_received": received,
        "states_dropped": max(0, published - received),
    }


ADDED_SUFFIXES = (f"/{ANNOTATIONS_SUFFIX}", f"/{SCENE_SUFFIX}", "/model")


def without_the_additions(message):
    """A message as it was before the view drew the robot: no corners, no candidate arm, no
    way."""
    if isinstance(message, MarkerDetections):
        return message.model_copy(
            update={
                "markers": tuple(m.model_copy(update={"corners": None}) for m in message.markers)
            }
        )
    if isinstance(message, SupervisorStatus):
        return message.model_copy(update={"candidate_arm": None, "way": ()})
    return message


def recording_cost(path: Path, robot: MobileManipulator, directory: Path) -> dict:
    """Bytes per simulated second of the recording rewritten with every view, and without
    what this view adds; the uncompressed bytes per simulated second of each added channel."""
    now, before = directory / "now.mcap", directory / "before.mcap"
    start, end = None, 0
    with SessionWriter(now, viewer=Viewer(robot)) as new, SessionWriter(before) as old:
        plain = Viewer()
        for recorded in read_session(path):
            if recorded.message is None:
                continue
            start = recorded.log_time_ns if start is None else min(start, recorded.log_time_ns)
            end = max(end, recorded.log_time_ns)
            new.write(recorded.key, recorded.message, recorded.log_time_ns, views=True)
            for entry in entries(
                recorded.key, without_the_additions(recorded.message), True, plain
            ):
                if not entry.channel.endswith(ADDED_SUFFIXES):
                    old.write_raw(entry, recorded.log_time_ns)
    seconds = (end - (start or 0)) / 1e9
    channels = info(now)["channels"]
    added = {
        c["key"].split("/", 1)[1]: round(c["bytes"] / seconds)
        for c in channels
        if c["key"].endswith(ADDED_SUFFIXES)
    }
    return {
        "sim_s": round(seconds, 1),
        "bytes_per_sim_s": round(now.stat().st_size / seconds),
        "bytes_per_sim_s_without_additions": round(before.stat().st_size / seconds),
        "added_channels_uncompressed_bytes_per_sim_s": added,
    }


def measure(runs: int) -> dict:
    if missing():
        raise SystemExit(f"studies.bench.live_view: {missing()}")
    with tempfile.TemporaryDirectory() as tmp:
        directory = Path(tmp)
        path = lockstep_profile(directory)
        profile = load_profile(path)
        rounds = []
        with (
            (directory / "launch.log").open("w") as log,
            launched(path, log) as launcher,
            connect(profile, launcher) as session,
        ):
            wait_alive(session, profile, launcher)
            wait_reached(session, profile, launcher)
            counter = Counter(session, profile.namespace)
            query.set_param(session, profile.namespace, "simulator", "paused", "false")
            for index in range(runs):
                alone = window(counter, session, profile.namespace)
                found = {"without": alone}
                for name, reads in (("layout", LAYOUT_CLIENT), ("every", EVERY_CHANNEL)):
                    with viewing(path, profile.namespace, reads) as (view, _, summary):
                        found[name] = window(counter, session, profile.namespace, view.pid)
                    found[f"{name}_view"] = summary
                rounds.append(found)
                print(
                    f"[bench] round {index + 1}: rtf {alone['rtf']} without the view, "
                    f"{found['layout']['rtf']} with a client of the layout, "
                    f"{found['every']['rtf']} with one of every channel",
                    file=sys.stderr,
                    flush=True,
                )
            stall = stalled_client(path, counter, profile.namespace)
        robot = MobileManipulator.from_yaml(profile.robot)
        recording = recording_cost(directory / "session.mcap", robot, directory)

    def median(name: str, field: str) -> float:
        return statistics.median(r[name][field] for r in rounds)

    def handler(name: str, field: str) -> float:
        return statistics.median(
            r[f"{name}_view"].get("handler_us", {}).get(field, 0.0) for r in rounds
        )

    summary = {
        "rtf_without": median("without", "rtf"),
        "loop_cpu_per_sim_s_without": median("without", "loop_cpu_per_sim_s"),
    }
    for name in ("layout", "every"):
        summary[name] = {
            "rtf": median(name, "rtf"),
            "rtf_ratio": round(median(name, "rtf") / summary["rtf_without"], 3),
            "loop_cpu_per_sim_s": median(name, "loop_cpu_per_sim_s"),
            "view_cpu_share": median(name, "view_cpu_share"),
            "view_cpu_per_sim_s": median(name, "view_cpu_per_sim_s"),
            "handler_us_median": handler(name, "median"),
            "handler_us_p99": handler(name, "p99"),
        }
    return {"rounds": rounds, **summary, "stalled_client": stall, "recording": recording}


def lines(report: dict) -> list[str]:
    rows = []
    for index, found in enumerate(report["rounds"], start=1):
        rows.append(
            [
                index,
                "none",
                found["without"]["rtf"],
                found["without"]["loop_cpu_per_sim_s"],
                None,
                None,
                None,
                None,
            ]
        )
        for name in ("layout", "every"):
            handler, window_ = found[f"{name}_view"].get("handler_us", {}), found[name]
            rows.append(
                [
                    index,
                    name,
                    window_["rtf"],
                    window_["loop_cpu_per_sim_s"],
                    window_["view_cpu_share"],
                    window_["view_cpu_per_sim_s"],
                    handler.get("median"),
                    handler.get("p99"),
                ]
            )
    stall, recording = report["stalled_client"], report["recording"]
    return [
        table(
            rows,
            [
                "round",
                "client reads",
                "loop rtf",
                "loop cpu s / sim s",
                "view cpu (cores)",
                "view cpu s / sim s",
                "handler us median",
                "handler us p99",
            ],
        ),
        *(
            f"medians, client of {name}: rtf {report[name]['rtf']} against "
            f"{report['rtf_without']} without a view (ratio {report[name]['rtf_ratio']}); view "
            f"{report[name]['view_cpu_per_sim_s']} cpu s per sim s against the loop's "
            f"{report['loop_cpu_per_sim_s_without']}, {report[name]['view_cpu_share']} cores; "
            f"handler {report[name]['handler_us_median']} us median, "
            f"{report[name]['handler_us_p99']} us p99"
            for name in ("layout", "every")
        ),
        f"stalled client {STALL_S:.0f} s: view rss {stall['rss_mb_before']} MB before, max "
        f"{stall['rss_mb_max']} MB, {stall['rss_mb_end']} MB at the end; robot states' "
        f"frames published {stall['states_published']}, received {stall['states_received']}, "
        f"dropped {stall['states_dropped']}",
        f"recording over {recording['sim_s']} sim s: {recording['bytes_per_sim_s']} B per sim s, "
        f"{recording['bytes_per_sim_s_without_additions']} without what the view adds",
        "added channels, uncompressed B per sim s: "
        + ", ".join(
            f"{k} {v}"
            for k, v in sorted(recording["added_channels_uncompressed_bytes_per_sim_s"].items())
        ),
    ]


def main(argv: list[str] | None = None) -> int:
    return run_bench(__doc__, measure, lines, 3, argv)


if __name__ == "__main__":
    sys.exit(main())
