"""What the simulator publishes each step: its sensors once per step (joint states and
odometry only where it publishes them, not where drivers do; the truth with its counters),
and a camera frame every 1/rate_hz of simulated time, the base marker hidden in the windows
asked for, a frame due while the last is still drawn skipped and counted in real time."""

from __future__ import annotations

import threading
from collections.abc import Iterator

import pytest
import yaml
import zenoh

from components.runtime import Node
from components.sim_outputs import SimOutputs
from components.simulator import Simulator
from messages import topics
from messages.camera import CameraFrame
from profiles.deploy_files import DEPLOY
from profiles.endpoints import free_port
from profiles.profile import load_profile
from profiles.profile_files import read_profile_data
from tests.components.conftest import Inbox
from vision.images import grey
from vision.markers import MarkerDetector

PERIOD_NS = 33_333_333
"""The scene's camera runs at 30 Hz."""
SENSORS = (topics.ARM_JOINT_STATES, topics.BASE_ODOMETRY, topics.SIM_TRUTH)


@pytest.fixture(scope="module")
def simulator(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Simulator]:
    """The simulator of deploy/sim.yaml (mono8 frames, its base marker hidden from 1 to 2 s),
    not started, on the session of its own router on loopback."""
    data = read_profile_data(DEPLOY / "sim.yaml")
    data["zenoh"]["router"] = [f"tcp/127.0.0.1:{free_port()}"]
    (spec,) = (c for c in data["components"] if c["name"] == "simulator")
    spec["params"].update(image_format="mono8", image_noise=0.0, hide_base_marker=[[1.0, 2.0]])
    path = tmp_path_factory.mktemp("sim_outputs") / "sim.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    profile = load_profile(path)
    with (
        zenoh.open(profile.zenoh.router_config()) as session,
        Node(profile, "simulator", Simulator.params, session=session) as node,
    ):
        made = Simulator(node)
        yield made
        made.shutdown()


def outputs(simulator: Simulator, writes=Simulator.writes, now_ns: int = 0) -> SimOutputs:
    s = simulator
    return SimOutputs(s.node, writes, s.world, s.robot, s.scene, s.obstacles, (), 508, now_ns)


def inboxes(simulator: Simulator) -> dict[str, Inbox]:
    node = simulator.node
    return {t.name: Inbox(node.session, node.namespace, t) for t in SENSORS}


def test_the_sensors_of_a_step_are_published_once(simulator: Simulator) -> None:
    out, seen = outputs(simulator), inboxes(simulator)
    for now_ns in (20_000_000, 20_000_000, 40_000_000, 40_000_000):
        out.sensors_of(now_ns)
    for inbox in seen.values():
        inbox.wait_for(lambda m: m.header.stamp_ns == 40_000_000, "of the second step")
        assert [m.header.stamp_ns for m in inbox.messages] == [20_000_000, 40_000_000]
        assert [m.header.seq for m in inbox.messages] == [0, 1]
    assert (
        simulator.node.counters["contacts"]
        == seen[topics.SIM_TRUTH.name].messages[-1].contacts
        == 0
    )
    out.shutdown()


def test_joints_and_odometry_are_not_published_where_drivers_publish_them(
    simulator: Simulator,
) -> None:
    writes = (topics.SIM_CLOCK, topics.CAMERA_IMAGE, topics.SIM_TRUTH)
    out, seen = outputs(simulator, writes), inboxes(simulator)
    out.sensors_of(20_000_000)
    seen[topics.SIM_TRUTH.name].wait_for(lambda m: True, "of the step")
    out.sensors_of(40_000_000)
    seen[topics.SIM_TRUTH.name].wait_for(lambda m: m.header.stamp_ns == 40_000_000, "later")
    assert seen[topics.ARM_JOINT_STATES.name].messages == []
    assert seen[topics.BASE_ODOMETRY.name].messages == []
    out.shutdown()


def test_a_frame_is_due_every_period_from_the_first(simulator: Simulator) -> None:
    out = outputs(simulator, now_ns=1_000)
    assert not out.frame_due(999) and out.frame_due(1_000)
    out.frame(1_000, lockstep=True)
    assert not out.frame_due(1_000 + PERIOD_NS - 1) and out.frame_due(1_000 + PERIOD_NS)
    out.shutdown()


def markers_seen(frame: CameraFrame, dictionary: int) -> set[int]:
    image = grey(frame.data, frame.encoding, frame.width, frame.height)
    return {d.id for d in MarkerDetector(dictionary).detect(image)}


def test_the_base_marker_is_hidden_in_its_window(simulator: Simulator) -> None:
    node = simulator.node
    frames = Inbox(node.session, node.namespace, topics.CAMERA_IMAGE)
    out = outputs(simulator)
    for now_ns in (500_000_000, 1_500_000_000, 2_000_000_000):  # before, in, at its end
        out.frame(now_ns, lockstep=True)
    frames.wait_for(lambda m: m.header.stamp_ns == 2_000_000_000, "after the window")
    scene = simulator.scene
    shown = [scene.base.id in markers_seen(f, scene.dictionary_id) for f in frames.messages]
    assert shown == [True, False, True]
    out.shutdown()


def test_a_frame_due_while_the_last_is_drawn_is_skipped_and_counted_in_real_time(
    simulator: Simulator,
) -> None:
    out = outputs(simulator)
    drawn, sent = threading.Event(), []
    out.camera.publish = lambda frame: (drawn.wait(10.0), sent.append(frame))
    out.frame(0, lockstep=False)
    out.frame(PERIOD_NS, lockstep=False)  # the first is still being drawn
    assert simulator.node.counters["frames_skipped"] == 1
    drawn.set()
    out.frame(2 * PERIOD_NS, lockstep=True)  # lockstep: waits for the last
    out.shutdown()
    assert [f.header.stamp_ns for f in sent] == [0, 2 * PERIOD_NS]
    assert simulator.node.counters["frames_skipped"] == 1
