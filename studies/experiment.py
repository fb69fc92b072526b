"""`parsimony experiment`: one chapter 6 experiment on the whole simulated loop.

It writes a profile that extends the simulation profile with the experiment's set-up
(``sim2d.scenarios``), the law and its gains, launches it (``parsimony launch``, its logs in
``DIR/launch.log``), unpauses the simulator once every component is alive, follows the run
on Zenoh (the controller's diagnostics, the supervisor's status), stops when the controller's
error has stayed under ``CONVERGED_ERROR`` for ``HOLD_S`` of simulated time or the time limit
passes, and judges the run from its recording, ``DIR/session.mcap``, alone (``analysis.judge``:
what ``parsimony report`` says of the same file), into ``DIR/report.json`` with the figures.

By default the simulator runs in lockstep as fast as the loop answers; ``realtime`` runs it
at the wall clock's pace instead, as ``make demo`` does.

To the judgement the report adds what only the launch knows: the real-time factor over the
followed run, each component's CPU time and handler durations, and the set-up.
"""

from __future__ import annotations

import dataclasses
import math
import os
import sys
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
import zenoh

import components.recorder  # noqa: F401 - loaded with this module, see below
import components.simulator  # noqa: F401
import components.state_estimator  # noqa: F401
import components.supervisor  # noqa: F401
import components.vision_tracker  # noqa: F401
from analysis.commands import commands_csv
from analysis.judge import JUDGED, judge, recording_check
from analysis.report import write_report
from analysis.run_end import CONVERGED_ERROR, HOLD_S, end_of_run, the_run
from components.cascade_controller import CascadeController
from components.lp_controller import LPController
from components.qp_controller import QPController
from launch import query
from messages.obstacles import Solids
from messages.topics import ROBOT_STATE
from outputs.files import written_whole
from outputs.stdout import json_text
from profiles.deploy_files import DEPLOY
from profiles.endpoints import free_port
from profiles.profile import Profile, ProfileError, load_profile
from profiles.recorder import recorder_component
from record.session_reader import info, make_whole
from record.sessions import load_session
from sim2d.scenarios import SimScenario, scenario
from studies.gain_sets import LP_PARAMS
from studies.launched import STARTUP_S, connect, launched, wait_alive, wait_reached
from studies.run_follower import Follower, follow
from wbc.laws.cascade_law import CascadeParams
from wbc.laws.lp_law import LPParams
from wbc.planar import inverse
from wbc.robot import MobileManipulator

# The components of the experiments' profiles are imported with this module (above): a study's
# worker loads them once, and the launcher forked for each of its runs (studies.launched)
# checks their dataflow on them and forks their shared process with them (launch.forked).
PROFILES = {
    "lp": DEPLOY / "sim.yaml",
    "cascade": DEPLOY / "sim_cascade.yaml",
    "qp": DEPLOY / "sim_qp.yaml",
}
"""The profile each controller runs in unless ``--profile`` names another."""
SUPERVISED = {name: DEPLOY / "sim_supervised.yaml" for name in ("anywhere", "blocked")}
"""Experiments whose LP runs under the staging supervisor (components/supervisor.py)."""
MODULES = {
    c.law_name: c.__module__.rsplit(".", 1)[-1]
    for c in (LPController, CascadeController, QPController)
}
"""The controller module of each law, as the controllers name themselves."""

TIME_LIMIT_S = 60.0
"""Simulated seconds after which a run that has not converged stops."""
LOCKSTEP_WATCHDOG_S = 30.0
"""Host seconds a component of a lockstep run may answer no status query before the launcher
takes it for hung (the profile's default is 10 s): the loop waits for its slowest member, and on a
machine shared with other work a sound controller was seen silent for 3 s, killed and restarted
mid-run, which cut its recording's diagnostics in two. The simulator waits as long for an answer
(``ack_timeout_s``, 2 s by default): a loaded machine once took a lockstep run past the default,
and a step given up changes the run; a process that dies is restarted, and the simulator gives up
what it owed 2 s after it is back (``components.lockstep_gate.RESTART_GRACE_S``)."""
SESSION_FILE = "session.mcap"
"""The recording of a run, beside its report."""


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
    robot: Path | None = None
    """The robot's description in place of the profile's (``robot:``): another robot is a
    profile change; its set-up is derived from it (``sim2d.scenarios.derived``)."""
    gains: Mapping[str, Any] = dataclasses.field(default_factory=dict)
    """Gains of the law (``GAINS``' names) that replace the experiment's: another law on the
    same set-up, such as another obstacle constraint (``obstacle_mode``) or the cascade held
    to the robot's bounds (``saturate``)."""
    figures: bool = True
    """Draw the report's figures into ``out`` (``analysis.report``): a study's runs, which keep
    their figures as numbers, skip the seconds they cost."""
    processes: str | None = None
    """The profile's ``processes``; by default ``shared`` in lockstep (its components but the
    recorder in one process: the run starts and stops faster, same commands) unless the profile
    says, and the profile's in real time."""


GAINS = {"lp": LPParams, "qp": LPParams, "cascade": CascadeParams}
"""The gains each controller takes (the QP reads the LP's), declared once with their bounds."""


def law_overrides(options: Options) -> dict[str, Any]:
    """The controller's gains: for the LP and the QP the experiment's LP gains that differ from
    the LP's defaults, then ``gains``; for the cascade ``gains`` over its declared defaults
    (appendix B's); an experiment under the supervisor takes its profile's. ``ProfileError``
    naming a gain the law does not have, or a value its declaration refuses."""
    given = dict(options.gains)
    params = GAINS[options.controller]
    law = "LP" if params is LPParams else options.controller
    names = [f.name for f in dataclasses.fields(params)]
    for name in given:
        if name not in names:
            raise ProfileError(f"no {law} gain {name!r}; the {law}'s gains are {', '.join(names)}")
    experiment = params is LPParams and options.name in LP_PARAMS
    try:  # each value checked against its declaration, then the gains together
        wanted = dataclasses.replace(LP_PARAMS[options.name] if experiment else params(), **given)
    except ValueError as error:
        raise ProfileError(f"gain {error}") from None
    if not experiment:
        return {name: getattr(wanted, name) for name in given}
    default = LPParams()
    return {
        name: getattr(wanted, name)
        for name in names
        if getattr(wanted, name) != getattr(default, name) or name in given
    }


def scene_overrides(
    setup: SimScenario, reference_pose: tuple[float, float, float]
) -> dict[str, Any]:
    """What the set-up changes in the profile's scene: its solids, moved from the simulator's
    world into F0 (which the simulator places at ``reference_pose``), and its goal marker's
    height and offset."""
    scene: dict[str, Any] = {}
    if setup.solids:
        in_f0 = tuple(solid.moved(*inverse(reference_pose)) for solid in setup.solids)
        scene["arm_obstacles"] = Solids.of(in_f0).model_dump(mode="json")
    goal: dict[str, Any] = {}
    if setup.goal_height is not None:
        goal["height_m"] = setup.goal_height
    if setup.goal_offset is not None:
        goal["offset"] = list(setup.goal_offset)
    return scene | ({"goal": goal} if goal else {})


def experiment_profile(options: Options, base: Path, setup: SimScenario) -> dict[str, Any]:
    """A profile extending ``base`` with the set-up, the law, lockstep or real time, its own
    namespace and router port (so it never meets another running system)."""
    simulator: dict[str, Any] = {**setup.sim_params(), "paused": True, "seed": options.seed or 0}
    simulator |= {
        "lockstep": not options.realtime,
        "real_time_factor": 1.0 if options.realtime else 0.0,
    }
    if not options.realtime:
        simulator["ack_timeout_s"] = LOCKSTEP_WATCHDOG_S
    if options.hide_base_marker is not None:
        simulator["hide_base_marker"] = [list(options.hide_base_marker)]
    controller = {"module": MODULES[options.controller], "params": law_overrides(options)}
    components = [
        recorder_component(options.out / SESSION_FILE),
        {"name": "simulator", "params": simulator},
        {"name": "state_estimator", "params": {"task": setup.task}},
        {"name": "controller", **controller},
    ]
    base_profile = load_profile(base)
    scene = (
        scene_overrides(setup, base_profile.scene.reference_pose)
        if base_profile.scene is not None
        else {}
    )
    if base_profile.component("simulator").module == "emulated_robot":
        if not options.realtime:
            raise ProfileError(
                f"{base}: a serial line carries no stamps, so the emulated "
                "devices run in real time only: add --realtime"
            )
        # The emulated devices' ports live in the run's directory: runs never share one.
        devices = options.out.resolve() / "devices"
        links = {"base_driver": devices / "create2", "arm_driver": devices / "servos"}
        simulator |= {
            "create_link": str(links["base_driver"]),
            "servo_link": str(links["arm_driver"]),
            "host_epoch": True,
        }
        components += [{"name": n, "params": {"port": str(p)}} for n, p in links.items()]
    robot = {"robot": str(options.robot.resolve())} if options.robot is not None else {}
    processes = options.processes
    if (
        processes is None
        and not options.realtime
        and "processes" not in base_profile.model_fields_set
    ):
        processes = "shared"
    return (
        {
            "extends": str(base.resolve()),
            **robot,
            "namespace": f"experiment{os.getpid()}",
            "startup_timeout_s": STARTUP_S,  # the launcher's and this module's wait are one
            **({} if options.realtime else {"watchdog_s": LOCKSTEP_WATCHDOG_S}),
            "zenoh": {"router": [f"tcp/127.0.0.1:{free_port()}"]},
            "components": components,
        }
        | ({"scene": scene} if scene else {})
        | ({"processes": processes} if processes else {})
    )


def say(text: str) -> None:
    """A line of progress on stderr."""
    print(f"[experiment] {text}", file=sys.stderr, flush=True)


def run_experiment(options: Options) -> dict[str, Any]:
    """Run one experiment; return its report (also written to ``out/report.json``)."""
    return judged_experiment(options)[0]


def judged_experiment(options: Options) -> tuple[dict[str, Any], dict[str, list]]:
    """Run one experiment; return its report (also written to ``out/report.json``) and the run
    it judged (``analysis.run_end.the_run`` of its recording)."""
    if options.name in SUPERVISED and options.controller != "lp":
        raise ProfileError(
            f"the {options.name} experiment runs the LP under the staging "
            "supervisor; the cascade cannot follow its drive tasks"
        )
    say(f"setting up the {options.name} experiment")
    base = options.profile or SUPERVISED.get(options.name) or PROFILES[options.controller]
    robot_file = options.robot or load_profile(base).robot
    robot = MobileManipulator.from_yaml(robot_file)
    try:
        setup = scenario(options.name, robot, options.seed)
    except ValueError as error:  # a set-up the robot has none of
        raise ProfileError(str(error)) from None
    composed = experiment_profile(options, base, setup)  # a bad gain is refused before
    options.out.mkdir(parents=True, exist_ok=True)  # anything is written
    profile_path = options.out / "profile.yaml"
    with written_whole(profile_path) as partial:  # whole once it exists: others wait on it
        partial.write_text(yaml.safe_dump(composed))
    profile = load_profile(profile_path)
    started = time.monotonic()
    names = [spec.name for spec in profile.start_order()]
    say(f"starting {starting(profile)} (their log: {options.out / 'launch.log'})")
    with (
        (options.out / "launch.log").open("w") as log,
        launched(profile_path, log, None) as launcher,
        connect(profile, launcher) as session,
    ):
        follower = Follower(session, profile.namespace)
        say(f"waiting for {', '.join(names)} to come alive")
        wait_alive(session, profile, launcher)
        say("waiting for every component to receive the paused simulator's clock")
        wait_reached(session, profile, launcher)
        before = component_counters(session, profile.namespace)
        query.set_param(session, profile.namespace, "simulator", "paused", "false")
        say(
            f"running until the error stays under {CONVERGED_ERROR} for {HOLD_S:g} s, at most "
            f"{options.time_limit_s:g} s of simulated time"
        )
        started = time.monotonic()
        (followed, truth_ns), wall_s = follow(
            follower, options.time_limit_s, options.realtime, started
        )
        # Held where the run ended: steps past it are neither judged nor worth the CPU time
        # they would take while the processes stop.
        query.set_param(session, profile.namespace, "simulator", "paused", "true")
        counters = component_counters(session, profile.namespace)
        say("stopping the processes (the recorder writes all it holds)")
    say("judging the recording")
    counters = {
        name: {**found, "run_cpu_ms": found["cpu_ms"] - before.get(name, found)["cpu_ms"]}
        for name, found in counters.items()
    }
    ran_s = (truth_ns[-1] - truth_ns[0]) / 1e9 if truth_ns else 0.0  # simulated s, as followed
    origin = truth_ns[0] / 1e9 if truth_ns else math.inf
    end_ns, _ = end_of_run(followed, options.time_limit_s, origin)
    path = options.out / SESSION_FILE
    facts = info(path)
    if not facts["complete"]:
        saved = make_whole(path)
        say(f"the recording had no footer: {saved} messages kept")
    recorded = load_session(path, JUDGED)
    start_ns = min((s.header.stamp_ns for s in recorded.get(ROBOT_STATE.name, [])), default=end_ns)
    report = {
        "experiment": options.name,
        "robot": robot.name,
        "controller": options.controller,
        "seed": options.seed,
        "mode": "realtime" if options.realtime else "lockstep",
        **judge(recorded, robot, options.time_limit_s),
        "wall_time_s": round(wall_s, 3),
        "real_time_factor": round(ran_s / wall_s, 2) if wall_s > 0 else None,
        "lockstep_timeouts": counters.get("simulator", {}).get("lockstep_timeouts", 0),
        "durations_us": durations(counters),
        "cpu_s": cpu_by_process(counters),
        "gains": dict(options.gains),
        "scenario": dataclasses.asdict(setup) | {"obstacles": setup.sim_params()["obstacles"]},
        "recording": recording_check(facts, (start_ns, end_ns)),
    }
    run, _ = the_run(recorded, options.time_limit_s)
    (options.out / "commands.csv").write_text(commands_csv(run, robot))
    report["figures"] = []
    if options.figures:
        label = options.controller
        say("drawing the figures")
        if report["recording"]["missing"]:
            label += " (RECORDING CUT SHORT: " + "; ".join(report["recording"]["missing"]) + ")"
        drawn = write_report([(label, run)], robot, options.out, profile.scene.reference_pose)
        report["figures"] = [str(path) for path in drawn["figures"]]
    (options.out / "report.json").write_text(json_text(report, indent=2))
    return report, run


def starting(profile: Profile) -> str:
    """What the launch starts: ``5 processes``, or ``5 components in 2 processes``."""
    count, shared = len(profile.start_order()), len(profile.shared())
    if not shared:
        return f"{count} processes"
    return f"{count} components in {count - shared + 1} processes"


def component_counters(session: zenoh.Session, namespace: str) -> dict[str, dict[str, int]]:
    """Every component's counters at the end of the run, and its ``pid``."""
    return {
        name: {**s.counters, "pid": s.pid} for name, s in query.statuses(session, namespace).items()
    }


def cpu_by_process(counters: dict[str, dict[str, int]]) -> dict[str, float]:
    """The CPU seconds of the run of each process, named by its component, or by its
    components joined with ``+`` when they share it (``processes: shared``)."""
    shared: dict[int, list[str]] = {}
    for name, found in sorted(counters.items()):
        shared.setdefault(found["pid"], []).append(name)
    return {
        "+".join(names): round(counters[names[0]]["run_cpu_ms"] / 1e3, 3)
        for names in shared.values()
    }


def durations(counters: dict[str, dict[str, int]]) -> dict[str, dict[str, int]]:
    """The ``*_us_median`` and ``*_us_p99`` counters of each component: its handlers' times
    and the simulator's answer times (``components.durations``)."""
    return {
        name: {k: v for k, v in sorted(found.items()) if k.endswith(("_us_median", "_us_p99"))}
        for name, found in sorted(counters.items())
    }
