"""Every robot of the zoo through what follows the running components: its recording, its
report, its robot scene; and a subset on the whole simulated loop.

Light, every robot (``ZOO``): a one-second closed loop of the controller's own step
(``components.control_step``, as ``parsimony rerun`` runs it) on the robot's derived pose goal,
its states integrated kinematically, recorded with the views (``record.session_file``): the
judge and the report read it by the robot's joint names, and the 3-D panel's model has a link
per joint. No processes: about 2 s of CPU per robot, most of it the report's figures.

Heavy, a subset (``WHOLE_LOOP``): the 7-joint arm on a differential base and the 5-joint arm on
an omnidirectional base, one lockstep ``parsimony experiment pose --robot NAME`` each, cut at
``TIME_LIMIT_S`` simulated seconds: vision (the camera renders the robot's markers, the tracker
finds them, the estimator fuses them), the recording and its report, ``parsimony rerun`` of the
recording (bit for bit; on the omnidirectional one), the recording's robot scene and its replay
into the live view (on the 7-joint one: both are processes of their own, a few seconds each). Why
these two: they are the two kinds of mobile base, and arm sizes, the whole loop had not run
(Little John's runs are test_experiment's); the other robots differ from them only in what
their description says, which the light checks read. One run per robot, shared by the module's
tests (a fixture of the module's scope): each costs a launch and a few simulated seconds.
"""

from __future__ import annotations

import asyncio
import csv
import io
import math
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from mcap.reader import make_reader

from analysis.commands import commands_csv
from analysis.judge import JUDGED, judge
from analysis.report import write_report
from analysis.run_end import the_run
from components.control_step import ControlStep
from components.lp_controller import LPController
from messages import topics
from messages.goal import Goal
from messages.header import Header
from messages.state import RobotState
from parsimony.commands.rerun import write_step
from profiles.deploy_files import DEPLOY, ROBOTS_DIR, zoo
from profiles.endpoints import free_port
from profiles.profile import load_profile
from record.session_file import SessionWriter, from_json
from record.session_reader import info
from record.sessions import load_session
from scenes.foxglove_views import MODEL_SUFFIX, View, Viewer
from sim2d.scenarios import scenario
from tests.parsimony.in_process import run_in_process
from tests.robot_states import state_at
from tests.scenes.views_read import decode
from tests.studies.experiments import run_here
from tests.view.live_view_client import DEADLINE_S, StderrLines, watch
from wbc.robot import MobileManipulator

ZOO = zoo()
WHOLE_LOOP = ("arm7_differential", "youbot")
"""The robots run on the whole simulated loop (the module docstring says why these)."""
TIME_LIMIT_S = 3.0
"""Simulated seconds of a whole-loop run: the estimator's fix and the arm's first moves."""
NAMESPACE = "zoo"
DT_NS = 20_000_000
STEPS = 50
"""The light loop's steps at 50 Hz: one second."""


def scene_goal(setup) -> np.ndarray:
    """x_d of a set-up over deploy/sim.yaml's scene (its own offset when it carries one)."""
    goal = load_profile(DEPLOY / "sim.yaml").scene.goal
    height = goal.height_m if setup.goal_height is None else setup.goal_height
    offset = goal.offset if setup.goal_offset is None else setup.goal_offset
    return setup.goal(height, offset)


def record_loop(robot: MobileManipulator, path: Path) -> None:
    """``STEPS`` of the LP's controller step on the robot's pose set-up, integrated
    kinematically, recorded with their views."""
    setup = scenario("pose", robot)
    stepper = ControlStep("lp", LPController.law_type, robot, LPController.gains_type())
    header = Header(stamp_ns=0, frame="world", seq=0, source="test")
    goal = Goal(header=header, task="pose", pose=tuple(scene_goal(setup)))
    stepper.take_goal(goal)
    q = np.array(setup.start)
    with SessionWriter(path, viewer=Viewer(robot)) as out:
        out.write(topics.CONTROL_GOAL.key(NAMESPACE), goal)
        for k in range(STEPS):
            head = Header(stamp_ns=(k + 1) * DT_NS, frame="world", seq=k, source="test")
            state = state_at(robot, q, head)
            out.write(topics.ROBOT_STATE.key(NAMESPACE), state, views=True)
            step = stepper.step(state, head.stamp_ns, math.inf)
            write_step(out, NAMESPACE, "lp", step, stepper.gains, robot.joint_names)
            assert step.output is not None, step.status
            q = q + step.output.u * DT_NS * 1e-9


@pytest.fixture(scope="module", params=ZOO, ids=[p.stem for p in ZOO])
def light(request: pytest.FixtureRequest, tmp_path_factory) -> tuple[MobileManipulator, Path]:
    robot = MobileManipulator.from_yaml(request.param)
    path = tmp_path_factory.mktemp(robot.name) / "session.mcap"
    record_loop(robot, path)
    return robot, path


def models(path: Path) -> list[dict]:
    """Every robot model the recording holds, decoded with nothing but its schema."""
    with path.open("rb") as file:
        return [
            decode(View(MODEL_SUFFIX, s.name, s.encoding, s.data, c.message_encoding, m.data))
            for s, c, m in make_reader(file).iter_messages()
            if c.topic.endswith(f"{topics.ROBOT_STATE.name}/{MODEL_SUFFIX}")
        ]


def assert_drawn(robot: MobileManipulator, path: Path, prefix: str = "estimate/") -> None:
    """The recording's model of the robot has its base and a link per joint."""
    found = models(path)
    assert found, "no robot model recorded"
    frames = {e["frame_id"] for e in found[-1]["entities"]}
    links = {f"{prefix}link_{i}" for i in range(1, robot.arm_dof + 1)}
    assert frames == {f"{prefix}base", *links}


def test_each_robots_recording_is_judged_and_reported_by_its_joint_names(
    light: tuple[MobileManipulator, Path], tmp_path: Path
) -> None:
    robot, path = light
    session = load_session(path, JUDGED)
    report = judge(session, robot)
    assert report["iterations"] == STEPS and report["effort"] is not None
    assert report["controller_statuses"] == {"optimal": STEPS}
    run, _ = the_run(session)
    rows = list(csv.reader(io.StringIO(commands_csv(run, robot))))
    lateral = ["lateral"] if robot.base.kind == "omnidirectional" else []
    base = ["stamp_s", "forward", "angular", *lateral]
    assert rows[0] == [*base, *(f"{n}_dot" for n in robot.joint_names)]
    assert len(rows) == STEPS + 1 and all(len(r) == len(base) + robot.arm_dof for r in rows)
    written = write_report([("lp", session)], robot, tmp_path)
    assert written["gaps"] == {}
    assert {p.name for p in written["figures"]} >= {"joints.png", "control_inputs.png"}
    other = MobileManipulator.from_yaml(ZOO[0] if ZOO[0].stem != robot.name else ZOO[-1])
    with pytest.raises(ValueError, match="the robot description"):  # by count, else by name
        write_report([("lp", session)], other, tmp_path / "other")


def test_each_robots_recording_draws_it_in_the_3d_panel(
    light: tuple[MobileManipulator, Path],
) -> None:
    robot, path = light
    assert_drawn(robot, path)


@pytest.fixture(scope="module", params=WHOLE_LOOP)
def whole(request: pytest.FixtureRequest, tmp_path_factory) -> tuple[str, dict, Path]:
    """One lockstep pose experiment of the robot on the whole loop: its report and folder."""
    out = tmp_path_factory.mktemp(request.param)
    report = run_here(
        out,
        "pose",
        robot=ROBOTS_DIR / f"{request.param}.yaml",
        time_limit_s=TIME_LIMIT_S,
        figures=request.param == "youbot",  # read by its rerun test; the other's by none
    )
    return request.param, report, out


@pytest.mark.heavy  # the whole loop, one run per robot shared by the module's tests
def test_the_robot_runs_the_whole_loop_seen_by_the_camera(whole: tuple[str, dict, Path]) -> None:
    name, report, out = whole
    assert report["robot"] == name and report["mode"] == "lockstep"
    assert report["truth"] == "recorded" and report["recording"]["whole"], report["recording"]
    assert report["contacts"] == 0 and report["joint_limit_violations"] == 0
    assert report["controller_statuses"].get("optimal", 0) > 0.9 * report["iterations"]
    assert report["invalid_states"] < report["iterations"] // 4  # the camera's fix came
    error = report["estimator_error"]
    assert error["samples"] > 0 and error["position_m"] < 0.02, error
    diagnostics = load_session(out / "session.mcap", JUDGED)[topics.CONTROL_DIAGNOSTICS.name]
    errors = [d.error_norm for d in diagnostics if d.error_norm is not None]
    assert errors[-1] < 0.5 * errors[0], (errors[0], errors[-1])  # on its way to the goal


@pytest.mark.heavy  # reads the module's whole-loop run: the omnidirectional base's lateral
@pytest.mark.parametrize("whole", ["youbot"], indirect=True)  # speed, the rows it adds
def test_its_recording_reruns_bit_for_bit_and_its_report_names_the_joints(
    whole: tuple[str, dict, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    name, _, out = whole
    robot = MobileManipulator.from_yaml(ROBOTS_DIR / f"{name}.yaml")
    rerun = tmp_path / "rerun.mcap"
    argv = ["rerun", str(out / "session.mcap"), "--controller", "lp", "--robot", name]
    code, _, err = run_in_process([*argv, "-o", str(rerun)], capsys)
    assert code == 0, err
    commands = {topics.ARM_COMMAND.name, topics.BASE_COMMAND.name}
    recorded, again = load_session(out / "session.mcap", commands), load_session(rerun, commands)
    for topic in commands:
        sent = {m.header.stamp_ns: m for m in recorded[topic]}
        offline = {m.header.stamp_ns: m for m in again[topic]}
        assert len(sent) > 100 and sent.keys() <= offline.keys(), topic
        values = [
            (offline[t].model_dump(exclude={"header"}), m.model_dump(exclude={"header"}))
            for t, m in sent.items()
        ]  # every value, the joints' names, a lateral speed
        assert all(a == b for a, b in values), topic
    assert {m.joint_names for m in again[topics.ARM_COMMAND.name]} == {robot.joint_names}
    assert (out / "joints.png").is_file()  # the experiment's report, by the robot's names
    header = (out / "commands.csv").read_text().splitlines()[0]
    assert header.endswith(",".join(f"{n}_dot" for n in robot.joint_names))


@pytest.mark.heavy  # reads the module's whole-loop run
def test_its_recording_draws_the_robot_and_its_truth(whole: tuple[str, dict, Path]) -> None:
    name, _, out = whole
    robot = MobileManipulator.from_yaml(ROBOTS_DIR / f"{name}.yaml")
    assert_drawn(robot, out / "session.mcap")
    channels = {c["key"] for c in info(out / "session.mcap")["channels"]}
    assert any(k.endswith(f"{topics.SIM_TRUTH.name}/{MODEL_SUFFIX}") for k in channels)


@pytest.mark.heavy  # reads the module's whole-loop run: one robot (a replay is the
@pytest.mark.parametrize("whole", ["arm7_differential"], indirect=True)  # same for any)
def test_its_replay_is_watched_live_with_the_robots_joints_and_model(
    whole: tuple[str, dict, Path], tmp_path: Path
) -> None:
    """`parsimony replay --view` of the run's recording, with the run's own profile (its robot),
    into a namespace of its own on a router of its own: a Foxglove client reads the states by
    the robot's joint names, and the robot's model drawn from its description."""
    name, _, out = whole
    robot = MobileManipulator.from_yaml(ROBOTS_DIR / f"{name}.yaml")
    profile = tmp_path / "replay.yaml"
    router = {"router": [f"tcp/127.0.0.1:{free_port()}"]}
    profile.write_text(yaml.safe_dump({"extends": str(out / "profile.yaml"), "zenoh": router}))
    port = free_port()
    replay = subprocess.Popen(
        [sys.executable, "-m", "parsimony.cli", "replay", str(out / "session.mcap")]
        + ["--profile", str(profile), "--loop", "--namespace", "zoo", "--view"]
        + ["--port", str(port)],
        stdin=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    said = StderrLines(replay)
    try:
        said.wait_for(" live at ")
        state_key = topics.ROBOT_STATE.key("zoo")
        model = f"{state_key}/{MODEL_SUFFIX}"
        _, first = asyncio.run(watch(f"ws://127.0.0.1:{port}", {state_key, model}))
        state = from_json(first[state_key][1], RobotState)
        assert state.joint_names == robot.joint_names and len(state.arm_joints) == robot.arm_dof
        assert first[model][1]  # the model, drawn from the profile's robot
    finally:
        replay.send_signal(signal.SIGINT)
        replay.wait(DEADLINE_S)
    assert "Traceback" not in said.all(), said.all()
