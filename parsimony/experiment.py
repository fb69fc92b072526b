"""`parsimony experiment`: one chapter 6 experiment on the whole simulated loop.

It writes a profile that extends the simulation profile with the experiment's set-up
(``sim2d.scenarios``), the law and its gains, launches it (``parsimony launch``, its logs in
``DIR/launch.log``), unpauses the simulator once every component is alive, follows the run
on Zenoh, stops when the controller's error has stayed under ``CONVERGED_ERROR`` for
``HOLD_S`` of simulated time or the time limit passes, and writes ``DIR/report.json``.

By default the simulator runs in lockstep as fast as the loop answers; ``realtime`` runs it
at the wall clock's pace instead, as ``make demo`` does.

The report judges the run against the simulator's ground truth, which no component of the
loop reads: the true end-effector error, the estimator's error in steady state (the last
``HOLD_S`` s), contacts, joints at their hard stops, obstacle clearance, and the control
effort of table 6.1 of the commands sent.
"""

from __future__ import annotations

import bisect
import contextlib
import dataclasses
import hashlib
import math
import os
import signal
import struct
import subprocess
import sys
import threading
import time
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import numpy as np
import yaml
import zenoh

from deploy import query
from messages import codec, process, topics
from parsimony.kinematic_demo import LP_PARAMS
from parsimony.sessions import load_session
from profiles.endpoints import free_port
from profiles.profile import Profile, ProfileError, load_profile
from record.report import READS, write_report
from record.session_file import info, recover
from sim2d.scenarios import SimScenario, scenario
from wbc import dq
from wbc.kinematic_run import effort_of
from wbc.lp_law import LPParams
from wbc.planar import in_frame, offset_pose, planar_pose, wrap
from wbc.robot import MobileManipulator
from wbc.supervisor_phase import Phase

DEPLOY = Path(__file__).resolve().parents[1] / "deploy"
PROFILES = {"lp": DEPLOY / "sim.yaml", "cascade": DEPLOY / "sim_cascade.yaml"}
"""The profile each controller runs in unless ``--profile`` names another."""
SUPERVISED = {"anywhere": DEPLOY / "sim_supervised.yaml"}
"""Experiments whose LP runs under the staging supervisor (components/supervisor.py)."""
MODULES = {"lp": "lp_controller", "cascade": "cascade_controller"}

CONVERGED_ERROR = 0.01
"""The controller's error norm ||e|| under which the goal counts as reached."""
HOLD_S = 2.0
"""Simulated seconds the error must stay under ``CONVERGED_ERROR``; also the steady state."""
TIME_LIMIT_S = 60.0
"""Simulated seconds after which a run that has not converged stops."""
STARTUP_S = 60.0
"""Host seconds the components may take to come up."""
RECORDER_STOP_S = 10.0
"""Host seconds a stopping recorder may go without progress before it is killed; it stops
after everything else and writes all that still waits for it, however long that takes."""
SESSION_FILE = "session.mcap"
"""The recording of a run, beside its report."""
LISTENED = ("sim/truth", "robot/state", "control/diagnostics", "base/command", "arm/command",
            "supervisor/status")  # fmt: skip


@dataclass(frozen=True)
class Options:
    name: str
    controller: str = "lp"
    out: Path = Path("runs/experiment")
    seed: int | None = None
    profile: Path | None = None
    realtime: bool = False
    time_limit_s: float = TIME_LIMIT_S
    hide_base_marker: tuple[float, float] | None = None


def law_overrides(options: Options) -> dict[str, Any]:
    """The LP gains of the experiment that differ from the law's defaults (the cascade's
    defaults are the dissertation's)."""
    if options.controller != "lp":
        return {}
    wanted, default = LP_PARAMS[options.name], LPParams()
    return {
        f.name: getattr(wanted, f.name)
        for f in dataclasses.fields(LPParams)
        if getattr(wanted, f.name) != getattr(default, f.name)
    }


def experiment_profile(options: Options, base: Path, setup: SimScenario) -> dict[str, Any]:
    """A profile extending ``base`` with the set-up, the law, lockstep or real time, its own
    namespace and router port (so it never meets another running system)."""
    simulator: dict[str, Any] = {**setup.sim_params(), "paused": True, "seed": options.seed or 0}
    simulator |= {"lockstep": not options.realtime,
                  "real_time_factor": 1.0 if options.realtime else 0.0}  # fmt: skip
    if options.hide_base_marker is not None:
        simulator["hide_base_marker"] = ", ".join(str(v) for v in options.hide_base_marker)
    controller = {"module": MODULES[options.controller], "params": law_overrides(options)}
    # Never restarted: a new recorder would begin the file again; a killed one's file recovers.
    recorder = {"name": "recorder", "module": "recorder", "role": "recorder",
                "stop_timeout_s": RECORDER_STOP_S, "restart": {"policy": "never"},
                "params": {"path": str((options.out / SESSION_FILE).resolve())}}  # fmt: skip
    components = [
        recorder,
        {"name": "simulator", "params": simulator},
        {"name": "state_estimator", "params": {"task": setup.task}},
        {"name": "controller", **controller},
    ]
    base_profile = load_profile(base)
    if base_profile.component("simulator").module == "emulated_robot":
        if not options.realtime:
            raise ProfileError(f"{base}: a serial line carries no stamps, so the emulated "
                               "devices run in real time only: add --realtime")  # fmt: skip
        # The emulated devices' ports live in the run's directory: runs never share one.
        devices = options.out.resolve() / "devices"
        links = {"base_driver": devices / "create2", "arm_driver": devices / "servos"}
        simulator |= {"create_link": str(links["base_driver"]),
                      "servo_link": str(links["arm_driver"]), "host_epoch": True}  # fmt: skip
        components += [{"name": n, "params": {"port": str(p)}} for n, p in links.items()]
    return {
        "extends": str(base.resolve()),
        "namespace": f"experiment{os.getpid()}",
        "zenoh": {"router": [f"tcp/127.0.0.1:{free_port()}"]},
        "components": components,
    }


class Recorder:
    """Every message of ``LISTENED`` in the namespace, decoded, in arrival order."""

    def __init__(self, session: zenoh.Session, namespace: str) -> None:
        self.messages: dict[str, list] = {name: [] for name in LISTENED}
        self._lock = threading.Lock()
        self._subscribers = [
            session.declare_subscriber(topics.TOPICS[name].key(namespace), self._taker(name))
            for name in LISTENED
        ]

    def _taker(self, name: str):
        topic = topics.TOPICS[name]

        def take(sample: zenoh.Sample) -> None:
            message = codec.decode(sample.payload.to_bytes(), topic.type)
            with self._lock:
                self.messages[name].append(message)

        return take

    def snapshot(self) -> dict[str, list]:
        with self._lock:
            return {name: list(values) for name, values in self.messages.items()}


def converged_at(diagnostics: list, statuses: list) -> float | None:
    """The simulated time since which every step's error stayed under ``CONVERGED_ERROR``;
    under a supervisor (``statuses`` of supervisor/status), only the steps of its last pose
    phase count: a drive leg's error is not the goal's."""
    pose_since = pose_phase_since(statuses)
    if pose_since is None:
        return None
    since = None
    for d in diagnostics:
        if d.header.stamp_ns / 1e9 < pose_since:
            continue
        small = d.status == "optimal" and d.error_norm is not None
        small = small and d.error_norm < CONVERGED_ERROR
        if not small:
            since = None
        elif since is None:
            since = d.header.stamp_ns / 1e9
    return since


def pose_phase_since(statuses: list) -> float | None:
    """When the supervisor's last run of pose (or reached) phases began; 0 with no supervisor,
    None while it is in another phase."""
    if not statuses:
        return 0.0
    since = None
    for status in statuses:
        if status.phase not in (Phase.POSE, Phase.REACHED):
            since = None
        elif since is None:
            since = status.header.stamp_ns / 1e9
    return since


def progress_line(messages: dict[str, list], wall_s: float) -> str:
    diagnostics = messages["control/diagnostics"]
    if not diagnostics:
        return f"[experiment] wall {wall_s:5.1f} s  waiting for the first control step"
    d = diagnostics[-1]
    t = d.header.stamp_ns / 1e9 - min(origin_s(messages), d.header.stamp_ns / 1e9)
    error = "-" if d.error_norm is None else f"{d.error_norm:.4f}"
    return (f"[experiment] sim {t:6.2f} s  wall {wall_s:5.1f} s  error {error}  "
            f"nonzero {d.nonzero}  {d.status}")  # fmt: skip


def run_experiment(options: Options) -> dict[str, Any]:
    """Run one experiment; return its report (also written to ``out/report.json``)."""
    if options.name in SUPERVISED and options.controller != "lp":
        raise ProfileError(f"the {options.name} experiment runs the LP under the staging "
                           "supervisor; the cascade cannot follow its drive tasks")  # fmt: skip
    base = options.profile or SUPERVISED.get(options.name) or PROFILES[options.controller]
    base_profile = load_profile(base)
    robot = MobileManipulator.from_yaml(base_profile.robot)
    setup = scenario(options.name, robot, options.seed)
    options.out.mkdir(parents=True, exist_ok=True)
    profile_path = options.out / "profile.yaml"
    profile_path.write_text(yaml.safe_dump(experiment_profile(options, base, setup)))
    profile = load_profile(profile_path)
    started = time.monotonic()
    with (options.out / "launch.log").open("w") as log,\
            launched(profile_path, log, None) as launcher,\
            connect(profile, launcher) as session:  # fmt: skip
        recorder = Recorder(session, profile.namespace)
        wait_alive(session, profile, launcher)
        wait_reached(session, profile, launcher)
        before = component_counters(session, profile.namespace)
        query.set_param(session, profile.namespace, "simulator", "paused", "false")
        started = time.monotonic()
        messages, wall_s = follow(recorder, options, started)
        counters = component_counters(session, profile.namespace)
    counters = {name: {**found, "run_cpu_ms": found["cpu_ms"] - before.get(name, found)["cpu_ms"]}
                for name, found in counters.items()}  # fmt: skip
    truth = messages["sim/truth"]  # the real-time factor: simulated over host s, as followed
    ran_s = truth[-1].header.stamp_ns / 1e9 - origin_s(messages) if truth else 0.0
    end_ns, converged = end_of_run(messages, options.time_limit_s, origin_s(messages))
    messages = until(messages, end_ns)
    report = build_report(options, setup, profile, robot, messages, (ran_s, wall_s), counters,
                          converged)  # fmt: skip
    write_commands(options.out / "commands.csv", messages)
    start_ns = min((s.header.stamp_ns for s in messages["robot/state"]), default=end_ns)
    facts = info(options.out / SESSION_FILE)
    report["recording"] = recording_check(facts, (start_ns, end_ns))
    if not facts["complete"]:
        whole_recording(options.out / SESSION_FILE)
    session = load_session(options.out / SESSION_FILE, READS)
    label = options.controller
    if report["recording"]["missing"]:
        label += " (RECORDING CUT SHORT: " + "; ".join(report["recording"]["missing"]) + ")"
    figures = write_report([(label, session)], robot, options.out,
                           profile.scene.reference_pose)["figures"]  # fmt: skip
    report["figures"] = [str(path) for path in figures]
    (options.out / "report.json").write_text(dumps(report))
    return report


@contextlib.contextmanager
def launched(profile_path: Path, log: IO[str] | int = subprocess.DEVNULL,
             stop_timeout_s: float | None = 30.0) -> Iterator[subprocess.Popen]:  # fmt: skip
    """``parsimony launch PROFILE`` as a child process, its output to ``log``; at the end of
    the block it is stopped by SIGINT (its components in order), killed after
    ``stop_timeout_s`` (None: the launcher's own limits, a recorder's progress, decide)."""
    launcher = subprocess.Popen(
        [sys.executable, "-m", "parsimony.cli", "launch", str(profile_path)],
        stdout=log,
        stderr=subprocess.STDOUT,
    )
    try:
        yield launcher
    finally:
        process.stop(launcher, signal.SIGINT, stop_timeout_s)


def connect(profile: Profile, launcher: subprocess.Popen) -> zenoh.Session:
    """A client session to the launch's router, once the router listens."""
    deadline = time.monotonic() + STARTUP_S
    while True:
        try:
            return query.Target(profile.namespace, profile.zenoh).open()
        except query.QueryError:
            if launcher.poll() is not None or time.monotonic() > deadline:
                raise
            time.sleep(0.2)  # the launcher opens its router first thing


def recording_check(facts: dict[str, Any], run_ns: tuple[int, int]) -> dict:
    """Whether the recording (``facts``: its ``info``) holds the whole run, from its first state
    to its last (``run_ns``): its footer, no sample dropped by the recorder, and the run's
    states from start to end; ``missing`` says what is not there (empty when whole). With its
    size, and bytes per simulated second."""
    start_ns, end_ns = run_ns
    missing = []
    if not facts["complete"]:
        missing.append("no footer: the recorder was killed, the file keeps its complete chunks")
    if facts["dropped"]:
        lost = ", ".join(f"{n} ({counter})" for counter, n in facts["dropped"].items())
        missing.append(f"the recorder lost {lost}")
    states = [c for c in facts["channels"] if c["key"].endswith("/" + topics.ROBOT_STATE.name)]
    first_ns = min((c["start_ns"] for c in states), default=0)
    last_ns = max((c["end_ns"] for c in states), default=0)
    if not states or first_ns > start_ns:
        missing.append(f"its states begin {(first_ns - start_ns) / 1e9:.2f} s after the run's")
    if last_ns < end_ns:
        missing.append(f"its states end {(end_ns - last_ns) / 1e9:.2f} s before the run's")
    span_s = max((end_ns - start_ns) / 1e9, 1e-9)
    return {"whole": not missing, "missing": missing, "messages": facts["messages"],
            "bytes": facts["bytes"], "bytes_per_sim_s": round(facts["bytes"] / span_s)}  # fmt: skip


def whole_recording(path: Path) -> None:
    """Make ``path``, whose recorder was killed before it wrote the footer, whole: every
    complete chunk is kept."""
    partial = path.with_suffix(".partial.mcap")
    path.rename(partial)
    saved = recover(partial, path)
    partial.unlink()
    print(f"[experiment] the recording had no footer: {saved} messages kept",
          file=sys.stderr)  # fmt: skip


def wait_alive(session: zenoh.Session, profile: Profile, launcher: subprocess.Popen) -> None:
    """Wait until every enabled component of the profile is alive."""
    wanted = {spec.name for spec in profile.components if spec.enabled}

    def missing() -> list[str]:
        return sorted(wanted - set(query.live_components(session, profile.namespace, 0.5)))

    wait_launch(launcher, missing, "did not come up")


def wait_reached(session: zenoh.Session, profile: Profile, launcher: subprocess.Popen) -> None:
    """Wait until every component that reads ``sim/clock`` has received the paused simulator's
    clock: a component's liveliness does not prove that the simulator's data reaches it yet,
    and one reached late would miss the first steps (the recorder, the first camera frame)."""

    def missing() -> list[str]:
        found = query.statuses(session, profile.namespace, 0.5)
        return [name for name, status in found.items()
                if status.counters.get("received.sim/clock", 1) == 0]  # fmt: skip

    wait_launch(launcher, missing, "never received the simulator's clock")


def wait_launch(launcher: subprocess.Popen, missing: Callable[[], list[str]], what: str) -> None:
    """Poll ``missing()``, the components still waited for, until it is empty; fail, naming
    them, when the launch stops or after ``STARTUP_S``."""
    deadline = time.monotonic() + STARTUP_S
    while waiting := missing():
        if launcher.poll() is not None:
            raise RuntimeError(f"the launch stopped (exit {launcher.returncode}); see its log")
        if time.monotonic() > deadline:
            raise RuntimeError(f"{', '.join(waiting)} {what} in {STARTUP_S:.0f} s")
        time.sleep(0.1)  # polling the router (liveliness tokens, the components' counters)


def follow(recorder: Recorder, options: Options, started: float) -> tuple[dict[str, list], float]:
    """Print progress until the run converges or its time is up; return what was received,
    and the host seconds since ``started`` when it was."""
    last_print = 0.0
    wall_limit = max(120.0, options.time_limit_s * (3.0 if options.realtime else 10.0))
    while True:
        time.sleep(0.2)  # progress is sampled, the data itself is all kept by the recorder
        messages = recorder.snapshot()
        wall = time.monotonic() - started
        if wall - last_print >= 1.0:
            print(progress_line(messages, wall), file=sys.stderr, flush=True)
            last_print = wall
        diagnostics = messages["control/diagnostics"]
        now_s = diagnostics[-1].header.stamp_ns / 1e9 if diagnostics else 0.0
        since = converged_at(diagnostics, messages["supervisor/status"])
        if since is not None and now_s - since >= HOLD_S:
            return messages, wall
        if now_s - origin_s(messages) >= options.time_limit_s or wall > wall_limit:
            return messages, wall


def component_counters(session: zenoh.Session, namespace: str) -> dict[str, dict[str, int]]:
    """Every component's counters at the end of the run."""
    return {name: dict(s.counters) for name, s in query.statuses(session, namespace).items()}


def durations(counters: dict[str, dict[str, int]]) -> dict[str, dict[str, int]]:
    """The ``*_us_median`` and ``*_us_p99`` counters of each component: its handlers' times
    and the simulator's answer times (``components.durations``)."""
    return {
        name: {k: v for k, v in sorted(found.items()) if k.endswith(("_us_median", "_us_p99"))}
        for name, found in sorted(counters.items())
    }


def origin_s(messages: dict[str, list]) -> float:
    """The simulated time the run started at: its first ground truth (0 in lockstep, the host's
    clock when the simulator keeps host time), s."""
    truth = messages["sim/truth"]
    return truth[0].header.stamp_ns / 1e9 if truth else math.inf


def end_of_run(messages: dict[str, list], time_limit_s: float, origin: float
               ) -> tuple[int, bool]:  # fmt: skip
    """The stamp (ns) a run ends at, ``HOLD_S`` after it converged, else the time limit (a
    simulated time: two lockstep runs of one set-up report the same steps); and whether it
    converged."""
    diagnostics = messages["control/diagnostics"]
    since = converged_at(diagnostics, messages["supervisor/status"])
    if since is not None and diagnostics[-1].header.stamp_ns / 1e9 - since >= HOLD_S:
        return round((since + HOLD_S) * 1e9), True
    return round((origin + time_limit_s) * 1e9), False


def until(messages: dict[str, list], end_ns: int) -> dict[str, list]:
    """The messages stamped up to ``end_ns``."""
    return {n: [m for m in ms if m.header.stamp_ns <= end_ns] for n, ms in messages.items()}


def true_goal(setup: SimScenario, profile: Profile) -> np.ndarray:
    """x_d in the simulator's world: the bin marker's pose times the scene's offset (eq. 6.3)."""
    scene = profile.scene
    bin_pose = planar_pose(*setup.bin[:2], setup.bin[2], scene.goal.height_m)
    return dq.normalize(dq.mul(bin_pose, offset_pose(*scene.goal.offset)))


def build_report(
    options: Options, setup: SimScenario, profile: Profile, robot: MobileManipulator,
    messages: dict[str, list], ran: tuple[float, float], counters: dict[str, dict[str, int]],
    converged: bool,
) -> dict[str, Any]:  # fmt: skip
    """The run's report; ``ran`` is (simulated s, host s) of the run when it was last followed,
    from the start to its last ground truth then (the real-time factor's two terms)."""
    truth, states = messages["sim/truth"], messages["robot/state"]
    diagnostics = messages["control/diagnostics"]
    sim_s = (truth[-1].header.stamp_ns - truth[0].header.stamp_ns) / 1e9 if truth else 0.0
    end_s = diagnostics[-1].header.stamp_ns / 1e9 if diagnostics else 0.0
    goal = true_goal(setup, profile)
    final_error = None
    if truth:
        x = np.array(truth[-1].end_effector)
        if setup.task == "pose":
            final_error = float(np.linalg.norm(x - dq.nearest_equivalent(goal, x)))
        else:
            final_error = float(np.linalg.norm(dq.translation(x) - dq.translation(goal)))
    steps = [d for d in diagnostics if d.status == "optimal"]
    solve = np.array([d.solve_time_us for d in steps]) if steps else np.zeros(1)
    return {
        "experiment": options.name,
        "controller": options.controller,
        "seed": options.seed,
        "mode": "realtime" if options.realtime else "lockstep",
        "converged": converged,
        "final_error": final_error,
        "final_error_estimated": diagnostics[-1].error_norm if diagnostics else None,
        "sim_time_s": round(sim_s, 3),
        "wall_time_s": round(ran[1], 3),
        "real_time_factor": round(ran[0] / ran[1], 2) if ran[1] > 0 else None,
        "iterations": len(diagnostics),
        "contacts": truth[-1].contacts if truth else 0,
        "supervisor": supervisor_summary(messages["supervisor/status"]),
        "joint_limit_violations": joints_at_stops(truth, robot),
        "min_obstacle_clearance_m": clearance(truth, setup, robot),
        "estimator_error": estimator_error(truth, states, profile, end_s - HOLD_S),
        "nonzero_entries": dict(sorted(Counter(d.nonzero for d in steps).items())),
        "effort": effort(messages, truth),
        "step_time_us": {
            "median": round(float(np.median(solve)), 1),
            "p99": round(float(np.percentile(solve, 99)), 1),
        },  # fmt: skip
        "lockstep_timeouts": counters.get("simulator", {}).get("lockstep_timeouts", 0),
        "durations_us": durations(counters),
        "cpu_s": {name: round(found["run_cpu_ms"] / 1e3, 3)
                  for name, found in sorted(counters.items())},  # fmt: skip
        "controller_statuses": dict(sorted(Counter(d.status for d in diagnostics).items())),
        "degraded_states": sum(s.degraded for s in states),
        "invalid_states": sum(not s.valid for s in states),
        "commands_digest": commands_digest(messages),
        "scenario": dataclasses.asdict(setup) | {"obstacles": setup.sim_params()["obstacles"]},
    }


def supervisor_summary(statuses: list) -> dict[str, Any] | None:
    """The staging supervisor's last word: phase, plans, re-plans, stalls, reason; and when
    each phase began (simulated s). None when the run had no supervisor."""
    if not statuses:
        return None
    last = statuses[-1]
    began: list[tuple[str, float]] = []
    for status in statuses:
        if not began or began[-1][0] != status.phase:
            began.append((status.phase, status.header.stamp_ns / 1e9))
    return {"phase": last.phase, "plans": last.plans, "replans": last.replans,
            "stalls": last.stalls, "reason": last.reason, "candidate_base": last.candidate_base,
            "phases": [{"phase": p, "from_s": t} for p, t in began]}  # fmt: skip


def joints_at_stops(truth: list, robot: MobileManipulator) -> int:
    """Ground-truth samples with an arm joint at (or past) its limit: the simulated servo's
    hard stop. The LP's joint constraint (5.14) keeps them inside."""
    if not truth:
        return 0
    arm = np.array([t.arm_joints for t in truth])
    low, high = robot.q_min[3:], robot.q_max[3:]
    return int(np.any((arm <= low + 1e-9) | (arm >= high - 1e-9), axis=1).sum())


def clearance(truth: list, setup: SimScenario, robot: MobileManipulator) -> float | None:
    """The least distance between the base's disc and an obstacle, m (None without obstacles)."""
    if not truth or not setup.obstacles:
        return None
    base = np.array([t.base_pose[:2] for t in truth])
    gaps = [np.hypot(base[:, 0] - o.x, base[:, 1] - o.y) - o.radius - robot.base.body_radius
            for o in setup.obstacles]  # fmt: skip
    return round(float(np.min(gaps)), 4)


class Truth:
    """The ground truth nearest a stamp (the same stamp in lockstep; on host time, as with
    emulated devices, the simulator's step nearest the driver's reading)."""

    def __init__(self, truth: list) -> None:
        self.samples = sorted(truth, key=lambda t: t.header.stamp_ns)
        self.stamps = [t.header.stamp_ns for t in self.samples]

    def at(self, stamp_ns: int, within_ns: int = 20_000_000):
        index = bisect.bisect_left(self.stamps, stamp_ns)
        near = [i for i in (index - 1, index) if 0 <= i < len(self.stamps)]
        if not near:
            return None
        best = min(near, key=lambda i: abs(self.stamps[i] - stamp_ns))
        return self.samples[best] if abs(self.stamps[best] - stamp_ns) <= within_ns else None


def estimator_error(truth: list, states: list, profile: Profile, since_s: float) -> dict:
    """The largest base position and heading error of the estimate against the truth, both in
    F0's frame, over the states stamped after ``since_s`` (the steady state)."""
    nearest = Truth(truth)
    position, angle = [], []
    for state in states:
        t = nearest.at(state.header.stamp_ns)
        if t is None or not state.valid or state.header.stamp_ns / 1e9 < since_s:
            continue
        x, y, phi = in_frame(*t.base_pose, profile.scene.reference_pose)
        position.append(math.hypot(state.base_pose[0] - x, state.base_pose[1] - y))
        angle.append(abs(wrap(state.base_pose[2] - phi)))
    if not position:
        return {"position_m": None, "angle_rad": None, "samples": 0}
    return {"position_m": round(max(position), 5), "angle_rad": round(max(angle), 5),
            "samples": len(position)}  # fmt: skip


def effort(messages: dict[str, list], truth: list) -> dict[str, float]:
    """Table 6.1's four metrics of the commanded u = [x', y', phi', q'] (x' = v cos phi,
    y' = v sin phi with the true heading at the command's stamp)."""
    nearest = Truth(truth)
    arm = {a.header.stamp_ns: a.joint_velocities for a in messages["arm/command"]}
    rows, stamps = [], []
    for b in messages["base/command"]:
        stamp = b.header.stamp_ns
        t = nearest.at(stamp)
        if stamp not in arm or t is None:
            continue
        phi = t.base_pose[2]
        v, w = b.forward_velocity, b.angular_velocity
        rows.append([v * math.cos(phi), v * math.sin(phi), w, *arm[stamp]])
        stamps.append(stamp)
    if len(rows) < 2:
        return {f"metric{i}": 0.0 for i in range(1, 5)}
    dt = float(np.median(np.diff(stamps))) / 1e9
    e = effort_of(np.array(rows), dt)
    values = (e.velocity_l1, e.velocity_l2, e.acceleration_l1, e.acceleration_l2)
    return {f"metric{i}": round(v, 4) for i, v in enumerate(values, start=1)}


def write_commands(path: Path, messages: dict[str, list]) -> None:
    """Every command pair the controller sent, one row per stamp (s, m/s, rad/s)."""
    arm = {a.header.stamp_ns: a.joint_velocities for a in messages["arm/command"]}
    lines = ["stamp_s,forward,angular," + ",".join(f"q{i}_dot" for i in range(1, 6))]
    for b in sorted(messages["base/command"], key=lambda c: c.header.stamp_ns):
        joints = arm.get(b.header.stamp_ns)
        if joints is not None:
            values = (b.forward_velocity, b.angular_velocity, *joints)
            lines.append(f"{b.header.stamp_ns / 1e9:.3f}," + ",".join(repr(v) for v in values))
    path.write_text("\n".join(lines) + "\n")


def commands_digest(messages: dict[str, list]) -> str:
    """SHA-256 of every command's stamp and values in stamp order: two runs that sent the same
    commands have the same digest."""
    digest = hashlib.sha256()
    for name in ("base/command", "arm/command"):
        for command in sorted(messages[name], key=lambda c: c.header.stamp_ns):
            values = command.model_dump(exclude={"header"})
            digest.update(struct.pack("<q", command.header.stamp_ns))
            digest.update(repr(sorted(values.items())).encode())
    return digest.hexdigest()


def dumps(report: dict) -> str:
    import json

    return json.dumps(report, indent=2)
