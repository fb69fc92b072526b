"""`parsimony view` as a control station, proved with Foxglove's own WebSocket client
(@foxglove/ws-protocol, run by node: ``tests/foxglove_client``) against a real view of a real
launched simulation (``deploy/sim_station.yaml``, lockstep, recorded): the robot's link frames,
the markers on the image, parameters from the client, and a goal from the client that the
supervisor takes and the robot reaches. Every protobuf message is read by Google's protobuf
with nothing but the schema its channel advertised."""

from __future__ import annotations

import base64
import json
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import yaml
import zenoh

from launch import query
from messages import codec, topics
from messages.goal import Goal
from profiles.deploy_files import DEPLOY
from profiles.profile import Profile, load_profile
from record.session_reader import info
from sim2d.scenarios import scenario
from studies.bench.live_view import lockstep_profile
from studies.launched import connect, launched, wait_alive, wait_reached
from tests.foxglove_client.client import FoxgloveClient, decode, missing, running_view
from tests.scenes.views_read import chain, pose_of
from view.client_limits import GOAL_RATE, STATUS_CHARS
from wbc import dq
from wbc.planar import in_frame, offset_pose, planar_pose
from wbc.robot import MobileManipulator

READY_S = 120.0
"""Host seconds the view may take to say where it listens (a loaded machine)."""
REACHED_M = 0.03
"""The true gripper this close to the client's goal counts as reached."""
SIM_CLOCK_LAG_NS = 1_000_000_000
"""How far behind the truth the view's copy of the simulator's clock may be, in simulated ns."""
GOAL_SHIFT_M = (-0.05, 0.08)
"""The client's goal stands this far from the bin (x, y in F0): the robot goes where the client
says, not where the bin is."""


@dataclass
class Station:
    profile: Profile
    address: str
    recording: Path
    session: zenoh.Session
    goals: list[Goal]
    """Every goal on goal/request, from a subscriber declared before the view started (its
    route is set up before any goal is sent)."""

    def key(self, suffix: str) -> str:
        return f"{self.profile.namespace}/{suffix}"


def paced(path: Path) -> None:
    """The simulator of the profile at ``path`` paced at the wall clock's rate, still in
    lockstep: the loop does not run flat out (two cores) while a test waits on the client."""
    data = yaml.safe_load(path.read_text())
    simulator = next(c for c in data["components"] if c["name"] == "simulator")
    simulator["params"]["real_time_factor"] = 1.0
    path.write_text(yaml.safe_dump(data))


@pytest.fixture(scope="module")
def station(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Station]:
    assert not missing(), missing()
    directory = tmp_path_factory.mktemp("station")
    path = lockstep_profile(directory, DEPLOY / "sim_station.yaml", "station")
    paced(path)
    profile = load_profile(path)
    with (
        (directory / "launch.log").open("w") as log,
        launched(path, log) as launcher,
        connect(profile, launcher) as session,
    ):
        goals: list[Goal] = []
        watcher = session.declare_subscriber(
            topics.GOAL_REQUEST.key(profile.namespace),
            lambda sample: goals.append(codec.decode(sample.payload.to_bytes(), Goal)),
        )
        wait_alive(session, profile, launcher)  # answered after the router has the watcher
        wait_reached(session, profile, launcher)
        with running_view(path, "--json", timeout_s=READY_S) as view:
            assert view.address in view.live_line, view.live_line  # where it listens
            query.set_param(session, profile.namespace, "simulator", "paused", "false")
            yield Station(profile, view.address, directory / "session.mcap", session, goals)
        watcher.undeclare()
    assert view.process.returncode == 0, view.err[-2000:]
    assert "Callback failed" not in view.err and "Traceback" not in view.err, view.err[-2000:]
    summary = json.loads(view.out)
    assert summary["shown"] > 0 and summary["malformed"] == 0, summary


@pytest.fixture
def client(station: Station) -> Iterator[FoxgloveClient]:
    with FoxgloveClient(station.address) as connected:
        connected.server_info()
        yield connected


def same_time(
    client: FoxgloveClient, first: str, second: str, found=lambda a, b: True
) -> tuple[dict, dict]:
    """Messages of ``first`` and ``second`` logged at one time, decoded, that ``found``
    accepts: the message and its view."""
    pair: list[tuple[dict, dict]] = []

    def matched(log_time: int, payload: bytes) -> bool:
        channels = client.channels()
        ours = decode(channels[second], payload)
        for time_, data in client.messages(first):
            if time_ == log_time:
                theirs = decode(channels[first], data)
                if found(theirs, ours):
                    pair.append((theirs, ours))
                    return True
        return False

    client.message(second, matched, f"{first} and {second} at one log time")
    return pair[0]


def test_the_robot_links_arrive_and_match_the_kinematics(
    station: Station, client: FoxgloveClient
) -> None:
    state_key, frames_key = station.key("robot/state"), station.key("robot/state/foxglove")
    model_key = station.key("robot/state/model")
    client.send("subscribe", topics=[state_key, frames_key, model_key])
    robot = MobileManipulator.from_yaml(station.profile.robot)
    # a state with the estimator's fix: before its first, the end effector is not known
    state, frames = same_time(client, state_key, frames_key, lambda state, _: state["valid"])
    by_child = {t["child_frame_id"]: t for t in frames["transforms"]}
    # world -> base -> link_0 -> ... -> link_5, each in the one before, as the DH chain.
    links = [f"estimate/link_{i}" for i in range(robot.arm_dof + 1)]
    composed = chain(by_child, ["estimate/base", *links], "world")
    q = np.array([*state["base_pose"], *state["arm_joints"]])
    for found, expected in zip(composed[1:], robot.frames(q), strict=True):
        assert np.allclose(
            found * np.sign(found[0] or 1), expected * np.sign(expected[0] or 1), atol=1e-9
        ), (found, expected)
    # The last link is the end effector the estimator gives.
    hand = pose_of(by_child["estimate/end_effector"])
    assert np.allclose(dq.translation(hand), dq.translation(composed[-1]), atol=1e-9)
    # The model: primitives fixed in those frames.
    _, payload = client.message(model_key)
    model = decode(client.channels()[model_key], payload)
    frames_drawn = {e["frame_id"] for e in model["entities"]}
    assert {"estimate/base", *(f"estimate/link_{i}" for i in range(1, 6))} <= frames_drawn
    assert all(e.get("frame_locked") for e in model["entities"])


def test_each_detected_marker_is_annotated_on_the_image(
    station: Station, client: FoxgloveClient
) -> None:
    markers_key = station.key("vision/markers")
    annotations_key = station.key("vision/markers/annotations")
    image_key = station.key("camera/image/foxglove")
    client.send("subscribe", topics=[markers_key, annotations_key, image_key])

    def after_an_image(markers: dict, _: dict) -> bool:
        """Two markers or more, found in an image that came after the client's first: the
        image of their stamp comes to the client too."""
        stamp = int(markers["header"]["stamp_ns"])
        return len(markers["markers"]) >= 2 and any(
            t <= stamp for t, _ in client.messages(image_key)
        )

    markers, annotations = same_time(client, markers_key, annotations_key, after_an_image)
    seen = markers["markers"]
    outlines = annotations["points"]
    assert len(outlines) == len(seen) == len(annotations["texts"])
    for marker, outline, text in zip(seen, outlines, annotations["texts"], strict=True):
        assert outline["type"] == "LINE_LOOP"
        corners = [[p.get("x", 0.0), p.get("y", 0.0)] for p in outline["points"]]
        assert np.allclose(corners, marker["corners"])
        assert text["text"] == f"id {marker['id']}"
    # On the image they were found in: the frame of their stamp.
    stamp = int(markers["header"]["stamp_ns"])
    client.message(image_key, lambda t, d: t == stamp, "the image the markers were found in")


def test_a_parameter_set_from_the_client_changes_the_controllers_diagnostics(
    station: Station,
    client: FoxgloveClient,
) -> None:
    client.send("getParameters", names=[], id="all")
    listed = client.wait_for(
        lambda e: e["event"] == "parameterValues" and e.get("id") == "all", "every parameter"
    )
    names = {p["name"] for p in listed["parameters"]}
    running = {spec.name for spec in station.profile.components if spec.enabled}
    assert {name.split(".")[0] for name in names} == running | {"control/stop"}  # the stop
    assert "controller.eta" in names and "supervisor.max_replans" in names
    diagnostics = station.key("control/diagnostics")
    client.send("subscribe", topics=[diagnostics])
    client.send(
        "setParameters",
        parameters=[{"name": "controller.eta", "value": 0.85, "type": "float64"}],
        id="eta",
    )
    answer = client.wait_for(
        lambda e: e["event"] == "parameterValues" and e.get("id") == "eta", "the new value"
    )
    assert answer["parameters"] == [{"name": "controller.eta", "type": "float64", "value": 0.85}]
    client.message(
        diagnostics,
        lambda t, d: json.loads(d)["parameters"]["eta"] == 0.85,
        "diagnostics with the new eta",
    )


def test_a_refused_set_says_why_and_keeps_the_value(
    station: Station, client: FoxgloveClient
) -> None:
    before = query.get_param(station.session, station.profile.namespace, "controller", "beta")
    client.send(
        "setParameters",
        parameters=[{"name": "controller.beta", "value": -3.0, "type": "float64"}],
        id="beta",
    )
    status = client.wait_for(
        lambda e: e["event"] == "status" and "controller.beta" in e["message"], "the refusal"
    )
    assert status["level"] == 2  # error
    assert "refused" in status["message"] and "expected a float in [" in status["message"]
    kept = client.wait_for(
        lambda e: e["event"] == "parameterValues" and e.get("id") == "beta", "the value kept"
    )
    assert kept["parameters"][0]["value"] == before


def client_goal_message(profile: Profile, robot: MobileManipulator) -> tuple[dict, np.ndarray]:
    """A PoseInFrame as the 3-D panel's publish-pose tool sends it (in F0, on the floor), near
    the bin of the pose experiment, and the true goal it means in the simulator's world."""
    scene = profile.scene
    assert scene is not None
    x, y, yaw = in_frame(*scenario("pose", robot).bin, scene.reference_pose)
    x, y = x + GOAL_SHIFT_M[0], y + GOAL_SHIFT_M[1]
    message = {
        "timestamp": {"sec": 0, "nsec": 0},
        "frame_id": "world",
        "pose": {
            "position": {"x": x, "y": y, "z": 0.0},
            "orientation": {"x": 0.0, "y": 0.0, "z": math.sin(yaw / 2), "w": math.cos(yaw / 2)},
        },
    }
    goal_f0 = dq.mul(planar_pose(x, y, yaw), offset_pose(*scene.goal.offset))
    f0 = planar_pose(*scene.reference_pose, scene.reference.height_m)
    return message, dq.mul(f0, goal_f0)


def test_a_goal_from_the_client_reaches_the_supervisor_and_the_robot_goes_there(
    station: Station,
    client: FoxgloveClient,
) -> None:
    info = client.server_info()
    assert "clientPublish" in info["capabilities"] and info["supportedEncodings"] == ["json"]
    robot = MobileManipulator.from_yaml(station.profile.robot)
    message, goal_in_sim = client_goal_message(station.profile, robot)
    request, status_key = station.key("goal/request"), station.key("supervisor/status")
    truth = station.key("sim/truth")
    client.send("subscribe", topics=[status_key, truth])
    # A goal in another frame is refused, and says why; only goal/request may be published.
    client.send(
        "advertise", topic=station.key("base/command"), encoding="json", schemaName="BaseCommand"
    )
    client.send("advertise", topic=request, encoding="json", schemaName="foxglove.PoseInFrame")
    channel = client.wait_for(
        lambda e: e["event"] == "advertised" and e["topic"] == request, "the client's channel"
    )["channel"]
    client.send("publish", channel=channel, text=json.dumps({**message, "frame_id": "camera"}))
    refused = client.wait_for(
        lambda e: e["event"] == "status" and "refused" in e["message"],
        "the refusal of a goal in the camera frame",
    )
    assert "frame_id 'camera'" in refused["message"] and refused["level"] == 2
    assert any(
        "only goal/request may be published" in e.get("message", "")
        for e in client.events
        if e["event"] == "status"
    )
    already = len(station.goals)
    start = len(client.events)
    client.send("publish", channel=channel, text=json.dumps(message))
    client.wait_for(lambda e: e["event"] == "status" and "sent" in e["message"], "the goal sent")
    # The supervisor has it: the goal is x_d = x_2 x_d^2 (eq. 6.3) at the published pose.
    client.wait_for(
        json_message(status_key, lambda status: status["plans"] >= 1),
        "the supervisor's plan of the client's goal",
        start,
    )
    (goal,) = station.goals[already:]
    f0 = planar_pose(
        *station.profile.scene.reference_pose, station.profile.scene.reference.height_m
    )
    assert goal.header.source == "view" and goal.task == "pose"
    assert np.allclose(np.array(goal.pose), dq.mul(dq.conj(f0), goal_in_sim), atol=1e-9)
    target = dq.translation(goal_in_sim)[1:]

    def near(log_time: int, payload: bytes) -> bool:
        hand = dq.translation(np.array(json.loads(payload)["end_effector"]))[1:]
        return float(np.linalg.norm(hand - target)) < REACHED_M

    reached, _ = client.message(
        truth, near, f"the true gripper within {REACHED_M} m of the client's goal"
    )
    client.send("unsubscribe", topics=[truth, status_key])
    # Stamped on the simulator's clock, as the truth is (not on the wall clock).
    first = min(t for t, _ in client.messages(truth))
    assert first - SIM_CLOCK_LAG_NS <= goal.header.stamp_ns <= reached, (first, reached)


HOSTILE_GOALS = [
    (
        '{"frame_id": "world", "pose": {"position": {"x": 1' + "0" * 400 + "}, "
        '"orientation": {"w": 1}}}',
        "pose.position.x = an integer of 401 digits is out of range",
    ),
    (
        '{"frame_id": "world", "pose": ' + "[" * 5000 + "]" * 5000 + "}",
        "not a goal: its JSON is nested too deeply",
    ),
    (
        '{"frame_id": "world", "pose": {"position": {"x": 1e154, "y": 1e154}, "orientation": '
        '{"w": 1}}}',
        "pose.position.x = 1e+154 is out of range: a goal lies within 1000 m of F0",
    ),
    ('{"frame_id": "world", "pose": {"orientation": {"w": 1}}}', "pose.position is missing"),
    (
        json.dumps({"frame_id": "f" * 1_000_000}),
        "a message of 1000016 bytes: a goal is at most 16384",
    ),
]
"""Goals the campaign sent, and what the station answers each: the first two got no answer
(the view raised), the third was '1.86e137 m below the floor', the last a 1 MB status."""


def test_each_hostile_goal_gets_a_short_refusal_and_none_reaches_the_supervisor(
    station: Station, client: FoxgloveClient
) -> None:
    assert len(HOSTILE_GOALS) <= GOAL_RATE.burst  # none dropped for its rate
    request = station.key("goal/request")
    client.send("advertise", topic=request, encoding="json", schemaName="foxglove.PoseInFrame")
    channel = client.wait_for(lambda e: e["event"] == "advertised", "the channel")["channel"]
    already = len(station.goals)
    for text, reason in HOSTILE_GOALS:
        start = len(client.events)
        client.send("publish", channel=channel, text=text)
        status = client.wait_for(
            lambda e: e["event"] == "status" and "goal/request" in e["message"],
            f"the answer to {reason!r}",
            start,
        )
        assert reason in status["message"] and status["level"] == 2, status
        assert len(status["message"]) <= STATUS_CHARS
    assert len(station.goals) == already


def json_message(topic: str, found: Callable[[dict], bool]) -> Callable[[dict], bool]:
    """Whether a client event is a message of ``topic`` whose JSON ``found`` accepts."""
    return lambda event: (
        event["event"] == "message"
        and event["topic"] == topic
        and found(json.loads(base64.b64decode(event["data"])))
    )


def test_the_recording_carries_the_robot_and_the_annotations(station: Station) -> None:
    """The recorder of the running system writes the same views (read as `parsimony info`
    reads a file still being written: every complete chunk)."""
    keys = {channel["key"]: channel for channel in info(station.recording)["channels"]}
    for suffix, schema in (
        ("robot/state/model", "foxglove.SceneUpdate"),
        ("robot/state/foxglove", "foxglove.FrameTransforms"),
        ("sim/truth/model", "foxglove.SceneUpdate"),
        ("vision/markers/annotations", "foxglove.ImageAnnotations"),
        ("supervisor/status/scene", "foxglove.SceneUpdate"),
    ):
        assert keys[station.key(suffix)]["schema"] == schema, sorted(keys)
