"""`parsimony experiment` on the whole simulated loop: real processes, real Zenoh on loopback,
real pymunk, real OpenCV detection of rendered ArUco markers, real HiGHS. Each run is judged
by the report against the simulator's ground truth, which no component of the loop reads."""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from mcap.reader import make_reader

from launch import query
from messages.obstacles import Plane
from profiles.profile import load_profile
from record.session_reader import info
from record.sessions import load_session
from scenes.foxglove_views import MODEL_EVERY, View
from sim2d.scenarios import scenario
from studies.experiment import (
    DEPLOY,
    LOCKSTEP_WATCHDOG_S,
    PROFILES,
    Options,
    connect,
    experiment_profile,
)
from tests.processes import process_gone
from tests.scenes.views_read import decode, vector
from wbc.planar import inverse
from wbc.planning.supervisor_phase import Phase
from wbc.robot import MobileManipulator

ONE_DEGREE = math.radians(1.0)


def experiment(out: Path, *arguments: str, stderr: list[str] | None = None) -> tuple[int, dict]:
    """Run `parsimony experiment ... --json`; its exit status and the report on its stdout
    (its stderr's lines added to ``stderr``)."""
    command = [sys.executable, "-m", "parsimony.cli", "experiment", *arguments, "--json"]
    done = subprocess.run(
        [*command, "--out", str(out)], capture_output=True, text=True, timeout=300
    )
    assert done.stdout.strip(), done.stderr[-2000:]
    if stderr is not None:
        stderr += done.stderr.splitlines()
    report = json.loads(done.stdout)
    assert report == json.loads((out / "report.json").read_text())
    return done.returncode, report


def assert_sound(report: dict) -> None:
    """What every converged run of the LP must show."""
    assert report["converged"], report
    assert report["contacts"] == 0
    assert report["joint_limit_violations"] == 0
    assert report["final_error"] < 0.02
    error = report["estimator_error"]
    assert error["samples"] > 50  # states of the steady state, 50 Hz
    assert error["position_m"] < 0.01 and error["angle_rad"] < ONE_DEGREE, error


def test_pose_experiment_with_the_lp_reaches_the_goal_seen_by_the_camera(tmp_path: Path) -> None:
    said: list[str] = []
    code, report = experiment(tmp_path, "pose", "--controller", "lp", "--seed", "1", stderr=said)
    assert code == 0
    assert_sound(report)
    # Each wait says what it waits for (before, 15-20 s of starting and stopping said nothing).
    steps = [
        "setting up the pose experiment",
        "starting 5 processes (their log: ",
        "waiting for recorder, simulator, vision_tracker, state_estimator, controller to "
        "come alive",
        "waiting for every component to receive the paused simulator's clock",
        "running until the error stays under 0.01 for 2 s, at most 60 s of simulated time",
        "stopping the processes",
        "judging the recording",
        "drawing the figures",
        "report: ",
    ]
    found = [
        next((i for i, line in enumerate(said) if line.startswith(f"[experiment] {step}")), None)
        for step in steps
    ]
    assert None not in found and found == sorted(found), said
    assert report["mode"] == "lockstep" and report["lockstep_timeouts"] == 0
    # Section 5.7: 6 task DOF + the nonholonomic equality, plus one per active constraint.
    histogram = {int(k): v for k, v in report["nonzero_entries"].items()}
    most = max(histogram, key=histogram.get)
    assert most in (7, 8), histogram
    assert max(histogram) <= 9, histogram
    for key in ("metric1", "metric2", "metric3", "metric4"):
        assert report["effort"][key] > 0.0
    assert report["step_time_us"]["median"] > 0.0
    assert report["iterations"] == sum(report["controller_statuses"].values())
    # The folder never disagrees with itself: `report` judges the file as `experiment` did.
    out = tmp_path / "again"
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "parsimony.cli",
            "report",
            str(tmp_path / "session.mcap"),
            "--out",
            str(out),
            "--json",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    judged = json.loads(done.stdout)["judged"]["lp"]
    assert judged == {key: report[key] for key in judged}
    assert json.loads((out / "effort.json").read_text())["lp"] == report["effort"]


def test_the_qp_controller_runs_the_pose_experiment_as_the_lp_does(tmp_path: Path) -> None:
    """deploy/sim_qp.yaml: the QP of the LP's rows and terms, a process like the others, reaches
    the goal seen by the camera; it spreads u over every entry (not parsimonious)."""
    code, report = experiment(tmp_path, "pose", "--controller", "qp")
    assert code == 0
    assert_sound(report)
    assert set(report["controller_statuses"]) <= {"optimal", "invalid state"}  # before a fix
    histogram = {int(k): v for k, v in report["nonzero_entries"].items()}
    assert max(histogram, key=histogram.get) == 8, histogram


def test_two_lockstep_runs_of_one_seed_send_bit_identical_commands(tmp_path: Path) -> None:
    # 3 simulated seconds each: 150 steps of the whole loop, with about 90 camera frames.
    _, first = experiment(tmp_path / "a", "position", "--seed", "3", "--time-limit", "3")
    _, second = experiment(tmp_path / "b", "position", "--seed", "3", "--time-limit", "3")
    assert first["commands_digest"] == second["commands_digest"]
    a = (tmp_path / "a" / "commands.csv").read_text()
    assert a == (tmp_path / "b" / "commands.csv").read_text()
    assert len(a.splitlines()) > 140
    _, other = experiment(tmp_path / "c", "position", "--seed", "4", "--time-limit", "3")
    assert other["commands_digest"] != first["commands_digest"]


def obstacle_rows(out: Path) -> tuple[set[str], set[str]]:
    """The obstacle modes the recorded controller ran with, and the obstacle rows it engaged."""
    diagnostics = load_session(out / "session.mcap", {"control/diagnostics"})
    steps = diagnostics["control/diagnostics"]
    modes = {d.parameters["obstacle_mode"] for d in steps}
    return modes, {c for d in steps for c in d.active_constraints if c.startswith("obstacle")}


def test_obstacle_experiment_with_the_lp_goes_round_the_obstacle_on_the_saddle_seed(
    tmp_path: Path,
) -> None:
    """Seed 772: start, obstacle and bin near one line, where 5.28 stalled by the obstacle.
    The default obstacle constraint, the vector-field inequality, takes the base round."""
    code, report = experiment(tmp_path, "obstacle", "--controller", "lp", "--seed", "772")
    assert code == 0
    assert_sound(report)
    assert report["min_obstacle_clearance_m"] > 0.0
    assert obstacle_rows(tmp_path) == ({"vector_field"}, {"obstacle_vector_field"})


def test_an_experiment_runs_the_obstacle_constraint_it_is_given(tmp_path: Path) -> None:
    """--gain obstacle_mode=border: the controller runs 5.28 instead, and goes round too."""
    code, report = experiment(tmp_path, "obstacle", "--gain", "obstacle_mode=border")
    assert code == 0
    assert_sound(report)
    assert obstacle_rows(tmp_path) == ({"border"}, {"obstacle_border"})


def test_table_experiment_reaches_over_the_edge_without_touching_the_table(tmp_path: Path) -> None:
    """The scene declares the table (in F0, the simulator places it in its world), the
    estimator publishes it, the LP's rows keep every collision part clear, and the simulator
    counts the penetrations from the true kinematics; blind to it, the LP reaches the same goal
    through the table's edge."""
    code, report = experiment(tmp_path / "guarded", "table")
    assert code == 0
    assert_sound(report)
    assert report["arm_penetrations"] == 0
    assert min(report["arm_clearance_m"].values()) > 0.0
    assert report["scenario"]["solids"][0]["name"] == "table"
    code, blind = experiment(tmp_path / "blind", "table", "--gain", "arm_obstacles=false")
    assert code == 0 and blind["converged"] and blind["gains"] == {"arm_obstacles": False}
    assert blind["arm_penetrations"] > 0 and min(blind["arm_clearance_m"].values()) < -0.01
    # What a user opening the runs sees: the table in Foxglove's 3-D panel, where the scene
    # puts it, sent at a low rate; the blind run's parts inside it in red; the clearance figure.
    # The scenario's table is in the simulator's world; the 3-D panel stands in F0 ("world").
    in_f0 = (
        Plane.model_validate(report["scenario"]["solids"][0])
        .solid()
        .moved(*inverse(load_profile(PROFILES["lp"]).scene.reference_pose))
    )
    guarded = tmp_path / "guarded" / "session.mcap"
    solids = scenes(guarded, "/world/obstacles/solids")
    obstacles = next(
        c["messages"] for c in info(guarded)["channels"] if c["key"].endswith("/world/obstacles")
    )
    assert 0 < len(solids) <= obstacles // MODEL_EVERY + 1, (len(solids), obstacles)
    for update in solids:
        (entity,) = update["entities"]
        top = np.array([vector(p, "xyz") for p in entity["triangles"][0]["points"]])
        assert entity["frame_id"] == "world"  # F0, where the scene declares it
        np.testing.assert_allclose(
            sorted(map(tuple, top[:, :2])), sorted(in_f0.footprint), atol=1e-9
        )
        assert top[:, 2] == pytest.approx(in_f0.offset)
    assert not any(u.get("entities") for u in scenes(guarded, "/sim/truth/penetrations"))
    inside = [
        u
        for u in scenes(tmp_path / "blind" / "session.mcap", "/sim/truth/penetrations")
        if u.get("entities")
    ]
    assert inside and all(u["entities"][0]["frame_id"] == "truth/world" for u in inside)
    for run in (report, blind):
        assert any(
            Path(f).name == "arm_clearance.png" and Path(f).stat().st_size > 10_000
            for f in run["figures"]
        )


def scenes(path: Path, suffix: str) -> list[dict]:
    """Every message of a recording's channel ending in ``suffix``, decoded with nothing but
    the schema written beside it."""
    with path.open("rb") as file:
        return [
            decode(
                View(
                    suffix,
                    schema.name,
                    schema.encoding,
                    schema.data,
                    channel.message_encoding,
                    message.data,
                )
            )
            for schema, channel, message in make_reader(file).iter_messages()
            if channel.topic.endswith(suffix)
        ]


def test_position_experiment_with_the_cascade_converges(tmp_path: Path) -> None:
    code, report = experiment(tmp_path, "position", "--controller", "cascade", "--seed", "2")
    assert code == 0 and report["converged"]
    assert report["contacts"] == 0


def test_hidden_base_marker_degrades_the_state_and_the_run_still_converges(
    tmp_path: Path,
) -> None:
    code, report = experiment(tmp_path, "pose", "--hide-base-marker", "1,4")
    assert code == 0
    assert_sound(report)
    assert report["degraded_states"] > 50  # about 2.5 s of 50 Hz states after the timeout


def kill_during_run(tmp_path: Path, component: str, name: str = "pose") -> tuple[int, dict, str]:
    """Start experiment ``name``, SIGKILL ``component`` once the controller has run 200 steps,
    and return the exit status, the report and the launch log."""
    command = [sys.executable, "-m", "parsimony.cli", "experiment", name, "--json"]
    process = subprocess.Popen(
        [*command, "--out", str(tmp_path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    try:
        found = statuses_while_moving(tmp_path, process, {component})
        os.kill(found[component].pid, signal.SIGKILL)
        stdout, _ = process.communicate(timeout=300)
    finally:
        if process.poll() is None:
            process.kill()
    return process.returncode, json.loads(stdout), (tmp_path / "launch.log").read_text()


def statuses_while_moving(out: Path, process: subprocess.Popen, wanted: set[str]) -> dict:
    """The statuses of the experiment writing into ``out``, once its controller has run 200
    steps and each of ``wanted`` has answered."""
    # No wall-clock deadline: the experiment ends by itself (its simulated time limit).
    while not (out / "profile.yaml").exists():
        assert process.poll() is None
        time.sleep(0.1)  # the experiment writes its profile before it launches
    target = query.Target.from_profile(out / "profile.yaml")
    with connect(load_profile(out / "profile.yaml"), process) as session:
        while True:
            assert process.poll() is None
            found = query.statuses(session, target.namespace, 0.5)
            steps = found.get("controller")
            moving = steps and steps.counters.get("published.arm/command", 0) > 200
            if moving and wanted <= set(found):  # a busy one may answer after 0.5 s
                return found


def test_a_killed_experiment_leaves_no_process_behind(tmp_path: Path) -> None:
    """`parsimony experiment` killed with -9 mid-run: its launcher sees it gone, stops every
    component in order (the recorder writes its footer) and exits; nothing runs on."""
    command = [sys.executable, "-m", "parsimony.cli", "experiment", "pose", "--json"]
    process = subprocess.Popen(
        [*command, "--out", str(tmp_path)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    try:
        found = statuses_while_moving(tmp_path, process, {"recorder", "simulator"})
        children = Path(f"/proc/{process.pid}/task/{process.pid}/children").read_text()
        pids = [int(pid) for pid in children.split()] + [s.pid for s in found.values()]
        process.kill()
        process.wait()
        for pid in pids:
            while not process_gone(pid):
                time.sleep(0.1)  # the test fails by hanging if one runs on
    finally:
        if process.poll() is None:
            process.kill()
    assert info(tmp_path / "session.mcap")["complete"], "the recorder wrote its footer"


def test_a_killed_estimator_stops_the_robot_is_restarted_and_the_run_converges(
    tmp_path: Path,
) -> None:
    code, report, log = kill_during_run(tmp_path, "state_estimator")
    assert code == 0 and report["converged"], report
    assert "state_estimator exited with -9; restart 1/" in log, log[-3000:]
    assert log.count("started state_estimator") == 2
    assert report["controller_statuses"].get("stale", 0) > 0  # zeros while no state came
    assert report["contacts"] == 0


def test_a_killed_vision_tracker_is_restarted_and_the_run_converges(tmp_path: Path) -> None:
    code, report, log = kill_during_run(tmp_path, "vision_tracker")
    assert code == 0 and report["converged"], report
    assert "vision_tracker exited with -9; restart 1/" in log, log[-3000:]
    assert log.count("started vision_tracker") == 2
    assert report["lockstep_timeouts"] >= 1  # the frame the dead tracker never answered


@pytest.mark.parametrize(
    "bad, why",
    [
        (["pose", "--seed", "x"], "--seed: expected an integer"),
        (["pose", "--seed", "-1"], "--seed: expected 0 to 2147483648, got -1"),
        (["pose", "--seed", str(2**31 + 1)], "--seed: expected 0 to 2147483648"),
        (["pose", "--time-limit", "nan"], "--time-limit: expected a finite number of seconds > 0"),
        (["pose", "--time-limit", "0"], "--time-limit: expected a finite number of seconds > 0"),
        (["pose", "--time-limit", "-3"], "--time-limit: expected a finite number of seconds > 0"),
        (["pose", "--profile", str(DEPLOY / "emulated.yaml")], "add --realtime"),
        (["jump"], "invalid choice: 'jump'"),
        (["pose"], "the following arguments are required: --out"),
        (["obstacle", "--gain", "obstacle_mode"], "--gain: expected NAME=VALUE"),
        (
            ["obstacle", "--gain", "obstacle_mode=around"],
            "LPParams.obstacle_mode: expected a str in {'border', 'vector_field', 'conservative'",
        ),
        (["obstacle", "--gain", "obstacle_radius=1"], "no LP gain 'obstacle_radius'"),
        (["obstacle", "--gain", "obstacle_gain=-1"], "LPParams.obstacle_gain: expected a float in"),
        (
            ["obstacle", "--controller", "cascade", "--gain", "obstacle_gain=1"],
            "no cascade gain 'obstacle_gain'; the cascade's gains are eta, offset",
        ),
        (
            ["pose", "--controller", "cascade", "--gain", "eta=-1"],
            "CascadeParams.eta: expected a float in",
        ),
        (
            ["pose", "--controller", "cascade", "--gain", "saturate=maybe"],
            "CascadeParams.saturate: expected a bool",
        ),
    ],
)
def test_usage_errors_exit_2_and_say_why(bad: list[str], why: str, tmp_path: Path) -> None:
    extra = [] if bad == ["pose"] else ["--out", str(tmp_path)]
    command = [sys.executable, "-m", "parsimony.cli", "experiment", *bad, *extra]
    done = subprocess.run(command, capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and why in done.stderr, done.stderr
    assert done.stdout == "" and "Traceback" not in done.stderr
    assert not any(tmp_path.iterdir())  # refused before anything was written


def test_the_cascade_takes_its_declared_gains(tmp_path: Path) -> None:
    """--gain with --controller cascade: the cascade's controller is given CascadeParams' gains
    (held to the robot's bounds with saturate), the LP's experiment gains none of them."""
    options = Options("pose", "cascade", out=tmp_path, gains={"eta": 1.0, "saturate": True})
    robot = MobileManipulator.from_yaml(load_profile(PROFILES["cascade"]).robot)
    profile = experiment_profile(options, PROFILES["cascade"], scenario("pose", robot))
    (controller,) = [c for c in profile["components"] if c["name"] == "controller"]
    assert controller == {
        "name": "controller",
        "module": "cascade_controller",
        "params": {"eta": 1.0, "saturate": True},
    }


def test_a_lockstep_run_is_not_killed_for_being_slow_on_a_busy_machine(tmp_path: Path) -> None:
    """In lockstep the launcher's watchdog waits LOCKSTEP_WATCHDOG_S for a status answer, not the
    profile's 3 s (a controller starved that long was killed and restarted mid-run); a run in
    real time keeps the profile's."""
    robot = MobileManipulator.from_yaml(load_profile(PROFILES["lp"]).robot)
    for realtime, watchdog_s in ((False, LOCKSTEP_WATCHDOG_S), (True, 3.0)):
        options = Options("pose", out=tmp_path, realtime=realtime)
        data = experiment_profile(options, PROFILES["lp"], scenario("pose", robot))
        written = tmp_path / "profile.yaml"
        written.write_text(yaml.safe_dump(data))
        assert load_profile(written).watchdog_s == watchdog_s


def test_an_experiment_does_not_write_over_a_directory_that_holds_files(tmp_path: Path) -> None:
    (tmp_path / "report.json").write_text("{}")
    command = [sys.executable, "-m", "parsimony.cli", "experiment", "pose", "--out", str(tmp_path)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and "give --force" in done.stderr, done.stderr
    assert (tmp_path / "report.json").read_text() == "{}"


def assert_behind(report: dict) -> None:
    """The goal (above the bin) lay behind the robot at the start: more than 90 degrees off
    its heading."""
    x, y, phi = report["scenario"]["start"][:3]
    goal_x, goal_y = report["scenario"]["bin"][:2]
    bearing = math.atan2(goal_y - y, goal_x - x) - phi
    assert abs(math.remainder(bearing, 2 * math.pi)) > math.pi / 2, report


def test_a_goal_behind_the_robot_is_reached_though_the_supervisor_is_killed_mid_run(
    tmp_path: Path,
) -> None:
    """The 'anywhere' experiment under the staging supervisor, SIGKILLed while it drives the
    first leg: restarted, it plans again from where the robot stands, and the LP reaches the
    goal behind the robot, round the obstacle, inside the joint limits."""
    code, report, log = kill_during_run(tmp_path, "supervisor", "anywhere")
    assert code == 0 and report["converged"], report
    assert "supervisor exited with -9; restart 1/" in log, log[-3000:]
    assert log.count("started supervisor") == 2
    assert_sound(report)
    assert_behind(report)
    assert report["min_obstacle_clearance_m"] > 0.0
    # Each process is idle until its first goal; then it plans and drives.
    phases = [p["phase"] for p in report["supervisor"]["phases"] if p["phase"] != "idle"]
    # After the last drive the phases run in their declared order (one already met at the
    # step its predecessor ends is skipped), and the run ends reached.
    after = phases[len(phases) - phases[::-1].index("drive") :]
    order = [Phase(p) for p in after]
    assert phases[:2] == ["planning", "drive"] and phases[-1] == "reached", phases
    assert order == sorted(order, key=list(Phase).index) and len(set(order)) == len(order), phases
    assert report["supervisor"]["replans"] == 0  # the restarted process plans once, afresh
