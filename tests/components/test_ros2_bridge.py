"""The ROS 2 bridge, in-process on a real Zenoh router (loopback), seen by a ROS 2 subscriber
written against rmw_zenoh's design document (0.2.5, Jazzy) alone: its keys
``<domain>/<topic>/<DDS type>/<RIHS01 hash>``, the 33-byte attachment, CDR decoded by rosbags
(not by ``ros2``'s code), the liveliness tokens ``@ros2_lv/...``; goals from ROS 2 reach the
supervisor's goal/request, and bad ones are refused, counted and never passed on."""

from __future__ import annotations

import math
import struct
import threading
import time
from collections.abc import Callable, Iterator

import numpy as np
import pytest
import yaml
import zenoh
import zenoh.ext

from components.ros2_bridge import Ros2Bridge
from components.runtime import Component, Node
from components.supervisor import Supervisor
from launch import query
from messages import codec, topics
from messages.camera import CameraFrame, CameraIntrinsics
from messages.header import Header
from profiles.deploy_files import DEPLOY, ROBOT_FILE
from profiles.profile_files import read_profile_data
from ros2.urdf import urdf
from tests.components.conftest import DEADLINE_S, System
from tests.robot_states import state_at
from tests.ros2.pose_stamped import pose_stamped
from tests.ros2.rmw_keys import ATTACHMENT, DOMAIN, design_key, store
from wbc import dq
from wbc.robot import MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
Q = np.array([1.0, 0.5, 0.3, 0.1, -0.4, 0.6, 0.2, 0.0])[: 3 + ROBOT.arm_dof]
JPEG = b"\xff\xd8\xff\xe0" + bytes(60) + b"\xff\xd9"


class RosSide:
    """Everything put under the domain's keys, with its attachment."""

    def __init__(self, session: zenoh.Session) -> None:
        self.samples: dict[str, list[tuple[bytes, bytes]]] = {}
        self._changed = threading.Condition()
        self._subscriber = session.declare_subscriber(f"{DOMAIN}/**", self._on_sample)

    def _on_sample(self, sample: zenoh.Sample) -> None:
        attachment = sample.attachment.to_bytes() if sample.attachment is not None else b""
        with self._changed:
            self.samples.setdefault(str(sample.key_expr), []).append(
                (sample.payload.to_bytes(), attachment)
            )
            self._changed.notify_all()

    def wait(self, key: str, count: int = 1) -> list[tuple[bytes, bytes]]:
        with self._changed:
            if not self._changed.wait_for(
                lambda: len(self.samples.get(key, ())) >= count, DEADLINE_S
            ):
                pytest.fail(f"nothing on {key}; saw {sorted(self.samples)}")
            return list(self.samples[key])

    def message(self, topic: str, msgtype: str, count: int = 1):
        data, _ = self.wait(design_key(topic, msgtype), count)[-1]
        return store().deserialize_cdr(data, msgtype)


class Bridge:
    """The bridge and the supervisor in this process, the router, and both sides of it."""

    def __init__(self, system: System, node: Node) -> None:
        self.system, self.node = system, node
        namespace = system.profile.namespace
        self.ros = RosSide(system.router)
        self.requests = system.inbox(topics.GOAL_REQUEST)
        self.state = system.router.declare_publisher(topics.ROBOT_STATE.key(namespace))
        self.goal_out = system.router.declare_publisher(
            design_key("goal_pose", "geometry_msgs/msg/PoseStamped")
        )

    def put(self, topic: topics.Topic, message) -> None:
        key = topics.key(self.system.profile.namespace, topic)
        self.system.router.put(key, codec.encode(message))

    def send_state(self) -> None:
        header = Header(stamp_ns=time.time_ns(), frame="world", seq=0, source="test")
        self.state.put(codec.encode(state_at(ROBOT, Q, header)))

    def counters(self) -> dict[str, int]:
        status = query.status_of(self.system.router, self.system.profile.namespace, "ros2_bridge")
        return status.counters

    def until(self, key: str, action: Callable[[], None]) -> None:
        """Do ``action`` again every 50 ms until something arrives on ``key``."""
        deadline = time.monotonic() + DEADLINE_S
        while not self.ros.samples.get(key):
            assert time.monotonic() < deadline, f"nothing on {key}"
            action()
            time.sleep(0.05)

    def wait_counter(self, name: str, at_least: int) -> dict[str, int]:
        deadline = time.monotonic() + DEADLINE_S
        while (counters := self.counters()).get(name, 0) < at_least:
            assert time.monotonic() < deadline, f"{name} stayed {counters.get(name)}"
            time.sleep(0.01)
        return counters


def declared(component: type[Component]) -> tuple:
    return component.params, component.reads, component.writes


@pytest.fixture(scope="module")
def bridge(deployed_for_module) -> Iterator[Bridge]:
    scene = read_profile_data(DEPLOY / "sim.yaml")["scene"]
    profile = {
        "namespace": "rosbridge",
        "zenoh": {"router": ["tcp/127.0.0.1:7447"]},
        "robot": "robots/little_john.yaml",
        "scene": scene,
        "components": [
            {
                "name": "supervisor",
                "module": "supervisor",
                "role": "controller",
                "enabled": False,
                "params": {"planning_budget_s": 0.05},
            },
            {
                "name": "ros2_bridge",
                "module": "ros2_bridge",
                "role": "tool",
                "enabled": False,
                "params": {"domain_id": DOMAIN, "goal_rate_hz": 100.0},
            },
        ],
    }
    system = deployed_for_module(yaml.safe_dump(profile))
    with (
        Node(system.profile, "supervisor", *declared(Supervisor)) as supervisor_node,
        Node(system.profile, "ros2_bridge", *declared(Ros2Bridge)) as node,
    ):
        supervisor = Supervisor(supervisor_node)
        supervisor_node.start(supervisor.shutdown, supervisor.clock_stalled)
        component = Ros2Bridge(node)
        node.start(component.shutdown)
        yield Bridge(system, node)


def every_topic_out(bridge: Bridge) -> None:
    """A state and a camera frame put until the bridge has published its topics of both."""
    bridge.send_state()
    intrinsics = CameraIntrinsics(fx=600.0, fy=600.0, cx=319.5, cy=239.5)
    header = Header(stamp_ns=time.time_ns(), frame="camera", seq=0, source="test")
    frame = CameraFrame(
        header=header, encoding="jpeg", width=640, height=480, data=JPEG, intrinsics=intrinsics
    )
    # the bridge reads the camera, and publishes a state, once it sees a ROS 2 reader
    bridge.until(
        design_key("camera/camera_info", "sensor_msgs/msg/CameraInfo"),
        lambda: bridge.put(topics.CAMERA_IMAGE, frame),
    )
    bridge.until(design_key("tf", "tf2_msgs/msg/TFMessage"), bridge.send_state)


def test_each_topic_is_on_its_design_key_with_the_attachment_and_rosbags_cdr(bridge):
    every_topic_out(bridge)

    joints = bridge.ros.message("joint_states", "sensor_msgs/msg/JointState")
    assert list(joints.name) == list(ROBOT.joint_names)
    assert np.allclose(joints.position, Q[3:])
    tf = bridge.ros.message("tf", "tf2_msgs/msg/TFMessage")
    pairs = {(t.header.frame_id, t.child_frame_id): t.transform for t in tf.transforms}
    base = pairs[("world", "base_footprint")].translation
    assert (base.x, base.y) == pytest.approx((Q[0], Q[1]))
    children = {child for _, child in pairs}
    assert {"base_link", "end_effector"} | {f"link_{i}" for i in range(1, 6)} <= children
    odom = bridge.ros.message("odom", "nav_msgs/msg/Odometry")
    assert (odom.pose.pose.position.x, odom.child_frame_id) == (
        pytest.approx(Q[0]),
        "base_footprint",
    )
    image = bridge.ros.message("camera/image/compressed", "sensor_msgs/msg/CompressedImage")
    assert (image.format, bytes(image.data)) == ("jpeg", JPEG)
    info = bridge.ros.message("camera/camera_info", "sensor_msgs/msg/CameraInfo")
    assert (info.width, info.height, info.k[0], info.header.frame_id) == (
        640,
        480,
        600.0,
        image.header.frame_id,
    )
    static = latched(bridge, "tf_static", "tf2_msgs/msg/TFMessage")
    assert [t.child_frame_id for t in static.transforms] == [image.header.frame_id]
    diagnostics = bridge.ros.message("diagnostics", "diagnostic_msgs/msg/DiagnosticArray")
    assert "parsimony/ros2_bridge" in [s.name for s in diagnostics.status]

    key = design_key("joint_states", "sensor_msgs/msg/JointState")
    attachments = [a for _, a in bridge.ros.wait(key)]
    sequence, stamp, length, gid = struct.unpack("<qqB16s", attachments[-1])
    assert (len(attachments[-1]), length, sequence) == (33, 16, len(attachments))
    assert abs(stamp - time.time_ns()) < DEADLINE_S * 1e9 and gid != bytes(16)


def test_every_payload_is_what_a_second_cdr_serialiser_writes(bridge):
    """Each message the bridge put, of every type, decoded by Foxglove's CDR serialiser
    (mcap-ros2-support, from the type's ros2msg text) and written again by it: the same bytes."""
    from mcap_ros2._dynamic import generate_dynamic, serialize_dynamic

    every_topic_out(bridge)
    bridge.ros.wait(design_key("diagnostics", "diagnostic_msgs/msg/DiagnosticArray"))
    payloads = {  # the bridge's own publications (the goals the tests put are not)
        key: [data for data, _ in samples]
        for key, samples in bridge.ros.samples.items()
        if "/goal_pose/" not in key
    }
    for topic, msgtype in (
        ("robot_description", "std_msgs/msg/String"),
        ("tf_static", "tf2_msgs/msg/TFMessage"),
    ):
        payloads[design_key(topic, msgtype)] = [latched_bytes(bridge, topic, msgtype)]
    checked = set()
    for key, samples in payloads.items():
        dds_type, type_hash = key.split("/")[-2:]
        package, _, _, name = dds_type.split("::")
        msgtype = f"{package}/msg/{name.removesuffix('_')}"
        assert type_hash == store().hash_rihs01(msgtype), key
        text, _ = store().generate_msgdef(msgtype, ros_version=2)
        decode, encode = generate_dynamic(msgtype, text)[msgtype], serialize_dynamic(msgtype, text)
        for data in samples[-3:]:
            assert encode[msgtype](decode(data)) == data, key
        checked.add(msgtype)
    assert {
        "sensor_msgs/msg/JointState",
        "tf2_msgs/msg/TFMessage",
        "nav_msgs/msg/Odometry",
        "sensor_msgs/msg/CompressedImage",
        "sensor_msgs/msg/CameraInfo",
        "std_msgs/msg/String",
        "diagnostic_msgs/msg/DiagnosticArray",
    } <= checked


def test_liveliness_tokens_are_the_golden_forms(bridge):
    zid = str(bridge.node.session.zid())
    tokens = {str(r.ok.key_expr) for r in bridge.system.router.liveliness().get("@ros2_lv/**")}
    prefix = f"@ros2_lv/{DOMAIN}/{zid}/0"
    assert f"{prefix}/0/NN/%/%/parsimony" in tokens

    def entity(kind: str, topic: str, msgtype: str, qos: str) -> bool:
        key = design_key(topic, msgtype).split("/", 2)[2]  # the DDS type and hash
        tail = f"{kind}/%/%/parsimony/%{topic.replace('/', '%')}/{key}/{qos}"
        return any(t.startswith(prefix + "/") and t.endswith(tail) for t in tokens)

    assert entity("MP", "joint_states", "sensor_msgs/msg/JointState", "::,10:,:,:,,")
    assert entity("MP", "robot_description", "std_msgs/msg/String", ":1:,1:,:,:,,")
    assert entity("MS", "goal_pose", "geometry_msgs/msg/PoseStamped", "::,10:,:,:,,")
    ids = [int(t.split("/")[4]) for t in tokens if t.startswith(prefix)]
    assert len(ids) == len(set(ids))  # one entity id each


def latched(bridge: Bridge, topic: str, msgtype: str):
    """The message a late joiner gets on a TRANSIENT_LOCAL topic (``latched_bytes``)."""
    return store().deserialize_cdr(latched_bytes(bridge, topic, msgtype), msgtype)


def latched_bytes(bridge: Bridge, topic: str, msgtype: str) -> bytes:
    """The payload a late joiner gets on a TRANSIENT_LOCAL topic, as rmw_zenoh's subscription
    asks for it: an advanced subscriber with history, detecting late publishers."""
    got: list[bytes] = []
    arrived = threading.Event()

    def on_sample(sample: zenoh.Sample) -> None:
        got.append(sample.payload.to_bytes())
        arrived.set()

    history = zenoh.ext.HistoryConfig(detect_late_publishers=True)
    key = design_key(topic, msgtype)
    with zenoh.ext.declare_advanced_subscriber(
        bridge.system.router, key, on_sample, history=history
    ):
        assert arrived.wait(DEADLINE_S), f"no /{topic} for a late joiner"
    return got[0]


def test_a_late_joiner_gets_the_robot_description(bridge):
    assert latched(bridge, "robot_description", "std_msgs/msg/String").data == urdf(ROBOT)


def test_a_pose_stamped_goal_reaches_the_supervisor_in_the_world(bridge):
    bridge.send_state()
    bridge.ros.message("tf", "tf2_msgs/msg/TFMessage")
    before = len(bridge.requests.messages)
    bridge.goal_out.put(pose_stamped("base_footprint", (0.5, 0.0, 0.4)), attachment=ATTACHMENT)
    goal = bridge.requests.wait_for(lambda _: len(bridge.requests.messages) > before, "goal")
    x, y, z = dq.translation(np.array(goal.pose))[1:]
    c, s = math.cos(Q[2]), math.sin(Q[2])
    assert (x, y, z) == pytest.approx((Q[0] + 0.5 * c, Q[1] + 0.5 * s, 0.4))
    assert goal.task == "pose" and bridge.wait_counter("goals_passed", 1)["goals_passed"] >= 1


def said(bridge: Bridge, name: str, match: Callable[[int, str], bool]) -> None:
    """Wait for /diagnostics to say of ``name`` what ``match`` (level, message) accepts."""
    key = design_key("diagnostics", "diagnostic_msgs/msg/DiagnosticArray")
    deadline, seen, last = time.monotonic() + DEADLINE_S, 0, None
    while True:
        arrays = bridge.ros.wait(key, seen + 1)
        for data, _ in arrays[seen:]:
            array = store().deserialize_cdr(data, "diagnostic_msgs/msg/DiagnosticArray")
            for status in array.status:
                if status.name == name:
                    last = (status.level, status.message)
                    if match(*last):
                        return
        seen = len(arrays)
        assert time.monotonic() < deadline, f"/diagnostics said {last} of {name}"


POSE_KEY = design_key("goal_pose", "geometry_msgs/msg/PoseStamped")
STRING_KEY = design_key("goal_pose", "std_msgs/msg/String")
GOOD = pose_stamped("world", (1.0, 0.0, 0.5))
BAD = {
    "cdr": ("malformed_cdr", POSE_KEY, b"\x00\x01\x00\x00\xff"),
    "too_many_bytes": ("malformed_cdr", POSE_KEY, GOOD + bytes(4096)),
    "frame": ("frame", POSE_KEY, pose_stamped("nowhere", (1.0, 0.0, 0.5))),
    "nan": ("goal", POSE_KEY, pose_stamped("world", (math.nan, 0.0, 0.5))),
    "quaternion": ("goal", POSE_KEY, pose_stamped("world", (1.0, 0.0, 0.5), (2.0, 0, 0, 0))),
    "hash": ("type_hash", POSE_KEY.rsplit("/", 1)[0] + "/RIHS01_" + "0" * 64, GOOD),
    "type": ("type_hash", STRING_KEY, GOOD),
}


@pytest.mark.parametrize(("kind", "key", "data"), BAD.values(), ids=BAD)
def test_a_bad_goal_is_refused_counted_said_and_nothing_moves(bridge, kind, key, data):
    before = bridge.counters()[f"refused.{kind}"]
    requests = len(bridge.requests.messages)
    bridge.system.router.put(key, data, attachment=ATTACHMENT)
    bridge.wait_counter(f"refused.{kind}", before + 1)
    said(bridge, "parsimony/ros2_bridge", lambda level, message: f"({kind})" in message)
    assert len(bridge.requests.messages) == requests  # a goal is refused or passed on, not both


def test_a_goal_the_supervisor_refuses_is_said_on_diagnostics_with_its_reason(bridge):
    far = pose_stamped("world", (40.0, 0.0, 0.5))
    bridge.goal_out.put(far, attachment=ATTACHMENT)
    bridge.send_state()  # the supervisor takes a goal on the state after it

    def refused(level: int, message: str) -> bool:
        """ERROR, the phase it gave the goal up in (refused at once, or unreachable when a plan
        was under way) and why: 'the goal is 39.0 m from the base...'."""
        bridge.send_state()
        phase, _, reason = message.partition(": ")
        return level == 2 and phase in ("refused", "unreachable") and "m from the base" in reason

    said(bridge, "parsimony/supervisor", refused)


def test_a_flood_of_goals_is_refused_past_the_rate(bridge):
    query.set_param(bridge.system.router, "rosbridge", "ros2_bridge", "goal_rate_hz", "0.01")
    before = bridge.counters()["refused.flood"]
    requests = len(bridge.requests.messages)
    for _ in range(20):
        bridge.goal_out.put(b"\x00", attachment=ATTACHMENT)
    bridge.wait_counter("refused.flood", before + 15)
    assert len(bridge.requests.messages) == requests
