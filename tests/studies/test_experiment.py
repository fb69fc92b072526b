"""`parsimony experiment` on the whole simulated loop: real processes, real Zenoh on loopback,
real pymunk, real OpenCV detection of rendered ArUco markers, real HiGHS. Each run is judged
by the report against the simulator's ground truth, which no component of the loop reads.
The runs through faults (components killed mid-run) are in test_experiment_faults."""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pytest
import yaml
from mcap.reader import make_reader

from messages.obstacles import Plane
from profiles.profile import Profile, load_profile
from record.session_reader import info
from record.sessions import load_session
from scenes.foxglove_views import MODEL_EVERY, View
from sim2d.scenarios import scenario
from studies.experiment import (
    DEPLOY,
    LOCKSTEP_WATCHDOG_S,
    PROFILES,
    Options,
    experiment_profile,
)
from tests.parsimony.in_process import run_in_process
from tests.scenes.views_read import decode, vector
from tests.studies.experiments import assert_sound, experiment, run_here
from wbc.planar import inverse
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(load_profile(PROFILES["lp"]).robot)
SHORT_RUN_S = 3.0
SHORT_RUN = {"time_limit_s": SHORT_RUN_S}
"""A run cut at 3 simulated seconds, for a test whose point comes in its first seconds (the
estimator's fix, the law's first rows engaged, the error falling), not at its convergence."""


@pytest.fixture(scope="module")
def pose(tmp_path_factory: pytest.TempPathFactory) -> tuple[int, dict, list[str], Path]:
    """`parsimony experiment pose --controller lp --seed 1 --hide-base-marker 1,4` as a user
    types it: its exit status, its report, its stderr's lines and its folder."""
    out = tmp_path_factory.mktemp("pose")
    said: list[str] = []
    code, report = experiment(
        out, "pose", "--controller", "lp", "--seed", "1", "--hide-base-marker", "1,4", stderr=said
    )
    return code, report, said, out


@pytest.mark.heavy  # the pose experiment on the whole loop, shared by the module's tests
def test_pose_experiment_with_the_lp_reaches_the_goal_seen_by_the_camera(
    pose: tuple, capsys: pytest.CaptureFixture[str]
) -> None:
    code, report, said, folder = pose
    assert code == 0
    assert_sound(report)
    # Each wait says what it waits for (before, 15-20 s of starting and stopping said nothing).
    steps = [
        "setting up the pose experiment",
        "starting 5 components in 2 processes (their log: ",
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
    # The folder never disagrees with itself: `report` judges the file as `experiment` did
    # (the command's own entry point, in this process: the fixture ran a Python start of it).
    out = folder / "again"
    code, shown, err = run_in_process(
        ["report", str(folder / "session.mcap"), "--out", str(out), "--json"], capsys
    )
    assert code == 0, err
    judged = json.loads(shown)["judged"]["lp"]
    assert judged == {key: report[key] for key in judged}
    assert json.loads((out / "effort.json").read_text())["lp"] == report["effort"]


def test_hidden_base_marker_degrades_the_state_and_the_run_still_converges(pose: tuple) -> None:
    """The base's marker hidden from 1 s to 4 s: the estimator goes on without it (its states
    said degraded), and the run still converges."""
    code, report, _, _ = pose
    assert code == 0
    assert_sound(report)
    assert report["degraded_states"] > 50  # about 2.5 s of 50 Hz states after the timeout


def test_two_lockstep_runs_of_one_seed_send_bit_identical_commands(
    pose: tuple, tmp_path: Path
) -> None:
    """A second run of the pose fixture's seed and hidden marker, stopped after 3 simulated
    seconds (150 steps of the whole loop, about 90 camera frames, the marker hidden for the last
    two), sends the very commands the first sent over those seconds, bit for bit: the first with
    its components in one process (a lockstep experiment's default), the second in one process
    each."""
    _, first, _, folder = pose
    marker = {"hide_base_marker": (1.0, 4.0)}
    again = run_here(tmp_path, "pose", seed=1, processes="separate", **marker, **SHORT_RUN)
    assert "recorder" in first["cpu_s"] and "controller" not in first["cpu_s"]  # one for four
    assert "controller" in again["cpu_s"]
    short = (tmp_path / "commands.csv").read_text().splitlines()
    assert len(short) > 140
    assert short == (folder / "commands.csv").read_text().splitlines()[: len(short)]
    # Each seed draws its own set-up (tests/sim2d/test_scenarios.py), and the runs ran seed 1's.
    drawn = asdict(scenario("pose", ROBOT, 1))
    for report in (first, again):
        assert report["scenario"]["start"] == pytest.approx(list(drawn["start"]))
        assert report["scenario"]["bin"] == pytest.approx(list(drawn["bin"]))


def test_the_qp_controller_runs_the_pose_experiment_as_the_lp_does(tmp_path: Path) -> None:
    """deploy/sim_qp.yaml: the QP of the LP's rows and terms, a process like the others, takes
    the robot towards the goal seen by the camera; it spreads u over every entry (not
    parsimonious). The run is cut at SHORT_RUN_S (the error falls from 0.64 to under 0.1 by
    then); that the QP reaches the goal of 6.2.1 is tests/wbc/laws/test_qp_law.py's."""
    report = run_here(tmp_path, "pose", controller="qp", **SHORT_RUN)
    assert report["contacts"] == 0 and report["joint_limit_violations"] == 0
    statuses = report["controller_statuses"]
    assert statuses["optimal"] > 0.9 * report["iterations"], statuses
    steps = load_session(tmp_path / "session.mcap", {"control/diagnostics"})["control/diagnostics"]
    first = next(i for i, d in enumerate(steps) if d.status == "optimal")
    # Before the camera's first fix the state is invalid (on a loaded machine the very first
    # step may find it stale); from the first solve on, every step is solved.
    assert {d.status for d in steps[first:]} == {"optimal"}, statuses
    assert first < 10, [d.status for d in steps[:first]]
    histogram = {int(k): v for k, v in report["nonzero_entries"].items()}
    assert max(histogram, key=histogram.get) == 8, histogram
    errors = [d.error_norm for d in steps if d.error_norm is not None]
    assert errors[-1] < 0.5 * errors[0], (errors[0], errors[-1])  # on its way to the goal
    # Not asked for figures (a study's runs are not): none drawn, the rest of the report whole.
    assert report["figures"] == [] and not list(tmp_path.glob("*.png"))
    assert (tmp_path / "commands.csv").is_file()


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
    report = run_here(tmp_path, "obstacle", seed=772)
    assert_sound(report)
    assert report["min_obstacle_clearance_m"] > 0.0
    assert obstacle_rows(tmp_path) == ({"vector_field"}, {"obstacle_vector_field"})


def test_an_experiment_runs_the_obstacle_constraint_it_is_given(tmp_path: Path) -> None:
    """--gain obstacle_mode=border: the controller runs 5.28 instead, its row engaged within
    the first simulated second (the run cut at SHORT_RUN_S; that 5.28 takes the base round to
    the goal is `parsimony demo`'s, tests/parsimony/commands/test_demo.py)."""
    report = run_here(tmp_path, "obstacle", gains={"obstacle_mode": "border"}, **SHORT_RUN)
    assert report["gains"] == {"obstacle_mode": "border"} and report["contacts"] == 0
    assert report["min_obstacle_clearance_m"] > 0.0
    assert obstacle_rows(tmp_path) == ({"border"}, {"obstacle_border"})


def test_table_experiment_reaches_over_the_edge_without_touching_the_table(tmp_path: Path) -> None:
    """The scene declares the table (in F0, the simulator places it in its world), the
    estimator publishes it, the LP's rows keep every collision part clear, and the simulator
    counts the penetrations from the true kinematics; blind to it, the LP goes through the
    table's edge within the first simulated second (the blind run cut at SHORT_RUN_S; that it
    reaches the goal so is `parsimony demo`'s, tests/parsimony/commands/test_demo.py)."""
    report = run_here(tmp_path / "guarded", "table", figures=True)
    assert_sound(report)
    assert report["arm_penetrations"] == 0
    assert min(report["arm_clearance_m"].values()) > 0.0
    assert report["scenario"]["solids"][0]["name"] == "table"
    blind = run_here(
        tmp_path / "blind", "table", gains={"arm_obstacles": False}, figures=True, **SHORT_RUN
    )
    assert blind["gains"] == {"arm_obstacles": False}
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
    report = run_here(tmp_path, "position", controller="cascade", seed=2)
    assert report["converged"]
    assert report["contacts"] == 0


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
def test_usage_errors_exit_2_and_say_why(
    bad: list[str], why: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The command's own entry point, in this process (a traceback would fail the test)."""
    extra = [] if bad == ["pose"] else ["--out", str(tmp_path)]
    code, out, err = run_in_process(["experiment", *bad, *extra], capsys)
    assert code == 2 and why in err and out == "", err
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
    profile's (a controller starved 3 s was killed and restarted mid-run); a run in real time
    keeps the profile's. A lockstep run's components share a process unless asked or its
    profile says otherwise; a run in real time keeps the profile's (one process each)."""
    robot = MobileManipulator.from_yaml(load_profile(PROFILES["lp"]).robot)
    default_s = Profile.model_fields["watchdog_s"].default
    separate = tmp_path / "separate.yaml"
    separate.write_text(f"extends: {PROFILES['lp']}\nprocesses: separate\n")
    for realtime, base, asked, watchdog_s, processes in (
        (False, PROFILES["lp"], None, LOCKSTEP_WATCHDOG_S, "shared"),
        (False, PROFILES["lp"], "separate", LOCKSTEP_WATCHDOG_S, "separate"),
        (False, separate, None, LOCKSTEP_WATCHDOG_S, "separate"),
        (True, PROFILES["lp"], None, default_s, "separate"),
    ):
        options = Options("pose", out=tmp_path, realtime=realtime, processes=asked)
        data = experiment_profile(options, base, scenario("pose", robot))
        written = tmp_path / "profile.yaml"
        written.write_text(yaml.safe_dump(data))
        profile = load_profile(written)
        assert (profile.watchdog_s, profile.processes) == (watchdog_s, processes)


def test_an_experiment_does_not_write_over_a_directory_that_holds_files(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "report.json").write_text("{}")
    code, _, err = run_in_process(["experiment", "pose", "--out", str(tmp_path)], capsys)
    assert code == 2 and "give --force" in err, err
    assert (tmp_path / "report.json").read_text() == "{}"
