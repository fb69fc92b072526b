"""The ROS 2 face of a profile: the robot's topics on the wire as rmw_zenoh writes them
(``ros2.participant``; ROS 2 Jazzy, rmw_zenoh_cpp 0.2.5), and goals from ROS 2 nodes.

A ROS 2 node ``parsimony`` in domain ``domain_id`` publishes, from the newest robot state
``max_rate_hz`` times a second, /joint_states, /tf (the base in the world, every link, the end
effector, and the goal's frame ``goal``) and /odom; /clock on simulated time; the ceiling
camera's frames (at most ``camera_rate_hz``) as /camera/image/compressed with
/camera/camera_info; /tf_static (the camera in the world) and /robot_description (the URDF),
both latched (TRANSIENT_LOCAL: a late joiner gets them); and /diagnostics: the controller's, the
supervisor's and the bridge's own status, every second and at once when a goal is refused.
The robot state, the camera's frames and the controller's diagnostics are kept as they come,
undecoded, and decoded only when published (``Newest``): the bridge costs the loop it watches
little, whatever the rate of its topics. Its timers run on its clock: with ``clock: wall`` in
its profile entry (``deploy/ros2.yaml``), host time, and it reads no sim/clock; the messages
keep the stamps of the states they come from (and ``/clock`` carries them when the profile
runs on simulated time).

It subscribes to /goal_pose (geometry_msgs/PoseStamped of the end effector, in a frame of the
TF tree) and passes each goal on goal/request, where the supervisor checks it as any goal
(``ros2.goal_in``; the access rules see the bridge as the Zenoh user ``ros2_bridge``). A goal
is refused, counted as ``refused.<kind>``, logged (rate-limited) and said on /diagnostics,
and nothing moves, when its key's type hash is not PoseStamped's (``type_hash``), it comes
faster than ``goal_rate_hz`` allows (``flood``), its bytes are not a PoseStamped's CDR
(``malformed_cdr``), its frame is not in the tree (``frame``) or its pose is not one
(``goal``). ``domain_id`` is read at start.
"""

from __future__ import annotations

import logging
import threading
import time
from functools import partial
from typing import Generic, TypeVar

import numpy as np
import zenoh
from pydantic import BaseModel

from components.joint_check import joints_match
from components.params import Param, ParamError, load_robot
from components.process_entry import run_component
from components.pubsub import Input
from components.runtime import Component, Node
from messages import codec, topics
from messages.camera import CameraFrame
from messages.goal import Goal
from messages.state import RobotState
from messages.supervisor import SupervisorStatus
from ros2 import bridge_messages as made
from ros2.goal_in import MAX_BYTES, Refused, goal_of
from ros2.participant import SENSOR_QOS, TRANSIENT_LOCAL_QOS, Participant
from ros2.state_messages import (
    JOINT_STATES,
    ODOM,
    TF,
    WORLD,
    frames,
    joint_state,
    odometry,
    tf_message,
    transform_stamped,
)
from ros2.urdf import joints, matrix, urdf
from sim2d.pinhole import ceiling_pose
from vision.images import jpeg
from wbc import dq

log = logging.getLogger("components.ros2_bridge")
M = TypeVar("M", bound=BaseModel)

NODE_NAME = "parsimony"
STATE_TOPICS = (JOINT_STATES, TF, ODOM, made.CLOCK)
"""What a state is published on (/clock on simulated time only)."""
REFUSALS = ("type_hash", "flood", "malformed_cdr", "frame", "goal")
DIAGNOSTICS_EVERY_S = 1.0
"""/diagnostics goes out at least this often (host seconds) while states come."""
GOAL_BURST = 3
"""Goals that may come at once before ``goal_rate_hz`` holds them back."""
JPEG_QUALITY = 80


class Newest(Generic[M]):
    """The newest payload of a topic the component reads (its remap followed), kept undecoded
    on Zenoh's thread and decoded when taken; one that does not decode is dropped, counted
    (``rejected.<topic>``) and logged, rate-limited, as a subscription's."""

    def __init__(self, node: Node, topic: topics.Topic[M]) -> None:
        self.node, self.topic = node, node.spec.topic(topic)
        self.key = self.topic.key(node.namespace)
        self._payload: zenoh.ZBytes | None = None
        self._kept: M | None = None
        node.counters.setdefault(f"rejected.{self.topic.name}", 0)
        # On the Zenoh thread that received it (no hand-over to a thread of its own): keeping
        # a reference is all it does.
        on_sample = zenoh.handlers.Callback(self._on_sample, indirect=False)
        self._subscriber = node.session.declare_subscriber(self.key, on_sample)

    def _on_sample(self, sample: zenoh.Sample) -> None:
        if sample.kind == zenoh.SampleKind.PUT and len(sample.payload) <= self.topic.max_bytes:
            self._payload = sample.payload

    def take(self, keep: bool = False) -> M | None:
        """The newest message not taken yet (None if none came since); with ``keep``, the
        newest taken so far when none came since."""
        payload, self._payload = self._payload, None
        if payload is None:
            return self._kept if keep else None
        try:
            self._kept = codec.decode(payload.to_bytes(), self.topic.type, self.key)
        except codec.DecodeError as error:
            self.node.count(f"rejected.{self.topic.name}")
            self.node.warn(f"rejected.{self.topic.name}", f"dropped a malformed message: {error}")
            return self._kept if keep else None
        return self._kept

    def close(self) -> None:
        """Stop reading the topic."""
        self._subscriber.undeclare()


class Ros2Bridge(Component):
    """robot/state, camera/image, supervisor/status, control/diagnostics -> ROS 2;
    /goal_pose -> goal/request."""

    reads = (
        Input(topics.ROBOT_STATE),
        Input(topics.CAMERA_IMAGE),
        Input(topics.SUPERVISOR_STATUS),
        Input(topics.CONTROL_DIAGNOSTICS),
        Input(topics.GOAL_REQUEST),
    )
    writes = (topics.GOAL_REQUEST,)
    params = (
        Param("domain_id", int, 0, low=0, high=232, doc="the ROS 2 graph's ROS_DOMAIN_ID"),
        Param("max_rate_hz", float, 30.0, low=1.0, high=1000.0, doc="states published a s"),
        Param("camera_rate_hz", float, 10.0, low=0.0, high=100.0, doc="images a s; 0: none"),
        Param("goal_rate_hz", float, 2.0, low=0.01, high=100.0, doc="most goals a host s"),
    )

    def __init__(self, node: Node) -> None:
        super().__init__(node)
        if node.profile.robot is None:
            raise ParamError("the ROS 2 bridge needs the profile's robot (robot:)")
        self.robot = load_robot(node.profile.robot)
        self.tree = joints(self.robot)
        scene = node.profile.scene
        camera = scene.camera if scene is not None else None
        self.camera_pose = ceiling_pose(*camera.position) if camera is not None else None
        for kind in REFUSALS:
            node.counters[f"refused.{kind}"] = 0
        node.counters |= {"refused_states": 0, "goals_passed": 0}
        self.last_refusal = ""
        self.latest: RobotState | None = None
        """The newest valid state published: the TF tree's frames are its (``tf_frames``)."""
        self.goal: Goal | None = None
        self.supervisor: SupervisorStatus | None = None
        self._lock = threading.Lock()
        self._tokens, self._filled_ns, self._flooded = float(GOAL_BURST), time.monotonic_ns(), 0
        self.goal_request = node.publisher(topics.GOAL_REQUEST)
        self._declare(int(node.params["domain_id"]), camera is not None)
        self.states = Newest(node, topics.ROBOT_STATE)
        self.frames_in: Newest[CameraFrame] | None = None
        """The camera's frames, read while a ROS 2 node reads /camera (``publish_image``)."""
        self.controller = Newest(node, topics.CONTROL_DIAGNOSTICS)
        node.subscribe(topics.SUPERVISOR_STATUS, self.on_supervisor)
        node.subscribe(topics.GOAL_REQUEST, self.on_goal)
        self.state_timer = node.timer(self._period("max_rate_hz"), self.publish_state)
        self.image_timer = node.timer(self._period("camera_rate_hz"), self.publish_image)
        node.timer(DIAGNOSTICS_EVERY_S, self.publish_diagnostics)

    def _declare(self, domain_id: int, camera: bool) -> None:
        """The ROS 2 node, its publishers (the latched ones put once) and its subscription."""
        ros = self.participant = Participant(self.node.session, NODE_NAME, domain_id)
        self.out = {
            topic: ros.publisher(*topic)
            for topic in (JOINT_STATES, TF, ODOM, made.DIAGNOSTICS)
            + ((made.CLOCK,) if self.node.profile.clock == "sim" else ())
        }
        if camera:
            self.out[made.COMPRESSED_IMAGE] = ros.publisher(*made.COMPRESSED_IMAGE, SENSOR_QOS)
            self.out[made.CAMERA_INFO] = ros.publisher(*made.CAMERA_INFO, SENSOR_QOS)
        latched = {
            made.ROBOT_DESCRIPTION: made.string(urdf(self.robot)),
            made.TF_STATIC: made.static_transforms(self.camera_pose, self.stamp_ns()),
        }
        for topic, message in latched.items():
            self.out[topic] = ros.publisher(*topic, TRANSIENT_LOCAL_QOS)
            self.out[topic].put(message)
        self.goal_key = ros.key(*made.GOAL_POSE)
        ros.subscription(*made.GOAL_POSE, self._on_ros_goal)

    def _period(self, name: str) -> float:
        """The period of a timer at the rate parameter ``name`` (at most 1 s: a rate of 0, no
        publishing, is looked at again every second)."""
        return 1.0 / max(1.0, float(self.node.params[name]))

    def stamp_ns(self) -> int:
        """The time of what the bridge says: the newest state's stamp (the system's time,
        simulated or the host's), else its clock's."""
        return self.latest.header.stamp_ns if self.latest else self.node.clock.now_ns()

    def tf_frames(self) -> dict[str, np.ndarray]:
        """Every frame of the TF tree as its 4x4 pose in the world: the robot's at the latest
        state (the world alone without one), the camera's, the goal's."""
        found = frames(self.latest, self.tree) if self.latest else {WORLD: np.eye(4)}
        if self.camera_pose is not None:
            found[made.CAMERA_FRAME] = matrix(self.camera_pose)
        if self.goal is not None:
            found[made.GOAL_FRAME] = self._goal_matrix(self.goal)
        return found

    def publish_state(self) -> None:
        """/joint_states, /tf, /odom (and /clock) of the newest state, if a new one came and a
        ROS 2 node reads one of them (the state is kept for goals either way)."""
        self.state_timer.period_ns = round(1e9 * self._period("max_rate_hz"))
        state = self.states.take()
        names = self.robot.joint_names
        if state is None or not state.valid:
            return
        if not joints_match(self.node, "refused_states", "robot/state", state.joint_names, names):
            return
        before, self.latest = self.latest, state
        if not any(self.out[topic].listened() for topic in STATE_TOPICS if topic in self.out):
            return
        stamp = state.header.stamp_ns
        tf = tf_message(state, self.tree)
        if self.goal is not None:
            goal = self._goal_matrix(self.goal)
            tf.transforms.append(transform_stamped(stamp, WORLD, made.GOAL_FRAME, goal))
        self.out[JOINT_STATES].put(joint_state(state, names))
        self.out[TF].put(tf)
        self.out[ODOM].put(odometry(state, before))
        if made.CLOCK in self.out:
            self.out[made.CLOCK].put(made.clock(stamp))

    @staticmethod
    def _goal_matrix(goal: Goal) -> np.ndarray:
        if goal.pose is not None:
            return matrix(np.array(goal.pose))
        where = np.eye(4)
        if goal.position is not None:
            where[:3, 3] = goal.position
        return where

    def publish_image(self) -> None:
        """The newest camera frame and its intrinsics, if a new one came. The frames are read
        only while a ROS 2 node subscribes to the camera's topics: an image costs the camera
        a copy to each reader."""
        self.image_timer.period_ns = round(1e9 * self._period("camera_rate_hz"))
        if made.COMPRESSED_IMAGE not in self.out:
            return
        wanted = float(self.node.params["camera_rate_hz"]) > 0.0 and (
            self.out[made.COMPRESSED_IMAGE].listened() or self.out[made.CAMERA_INFO].listened()
        )
        if wanted and self.frames_in is None:
            self.frames_in = Newest(self.node, topics.CAMERA_IMAGE)
        elif not wanted and self.frames_in is not None:
            self.frames_in.close()
            self.frames_in = None
        frame = self.frames_in.take() if self.frames_in is not None else None
        if frame is None:
            return
        if frame.encoding == "jpeg":
            data = frame.data
        else:
            pixels = np.frombuffer(frame.data, np.uint8).reshape(frame.height, frame.width, -1)
            data = jpeg(pixels[:, :, ::-1] if frame.encoding == "rgb8" else pixels, JPEG_QUALITY)
        self.out[made.COMPRESSED_IMAGE].put(made.compressed_image(frame, data))
        self.out[made.CAMERA_INFO].put(made.camera_info(frame))

    def on_supervisor(self, status: SupervisorStatus) -> None:
        """Keep the status; say a change of phase at once."""
        changed = self.supervisor is None or self.supervisor.phase != status.phase
        self.supervisor = status
        if changed:
            self.publish_diagnostics()

    def on_goal(self, goal: Goal) -> None:
        """The goal the supervisor is given (by the bridge or anyone): its frame on /tf."""
        self.goal = goal

    def publish_diagnostics(self) -> None:
        """/diagnostics: the controller's, the supervisor's and the bridge's status."""
        controller = self.controller.take(keep=True)
        statuses = [made.bridge_status(self.node.counters, self.last_refusal)]
        if self.supervisor is not None:
            statuses.insert(0, made.supervisor_status(self.supervisor))
        if controller is not None:
            statuses.insert(0, made.controller_status(controller))
        self.out[made.DIAGNOSTICS].put(made.diagnostic_array(self.stamp_ns(), statuses))

    def _on_ros_goal(self, sample: zenoh.Sample) -> None:
        """On Zenoh's thread: take the goal if the rate allows, else count a flood."""
        with self._lock:
            now = time.monotonic_ns()
            rate = float(self.node.params["goal_rate_hz"])
            self._tokens = min(GOAL_BURST, self._tokens + (now - self._filled_ns) * 1e-9 * rate)
            self._filled_ns = now
            if self._tokens < 1.0:
                self._flooded += 1
                if self._flooded == 1:
                    self.node.post(self._count_flood)
                return
            self._tokens -= 1.0
        key = str(sample.key_expr)
        size = len(sample.payload)  # not copied when too many for a goal
        data = sample.payload.to_bytes() if size <= MAX_BYTES else bytes(MAX_BYTES + 1)
        self.node.post(partial(self.on_ros_goal, key, data))

    def _count_flood(self) -> None:
        with self._lock:
            flooded, self._flooded = self._flooded, 0
        rate = float(self.node.params["goal_rate_hz"])
        self.refuse("flood", f"{flooded} goals faster than goal_rate_hz {rate:g}", flooded)

    def on_ros_goal(self, key: str, data: bytes) -> None:
        """A PoseStamped from ROS 2: on goal/request, or refused."""
        try:
            if key != self.goal_key:
                got = "/".join(key.split("/")[-2:])[:160]
                raise Refused("type_hash", f"{got} is not {self.goal_key.split('/', 2)[2]}")
            goal = goal_of(data, self.tf_frames(), self.node.header("world", self.stamp_ns()))
        except Refused as refused:
            self.refuse(refused.kind, str(refused))
            return
        self.goal_request.put(goal)
        self.node.count("goals_passed")
        x, y, z = dq.translation(np.array(goal.pose))[1:]
        log.info("a ROS 2 goal passed on: the end effector to (%.3f, %.3f, %.3f)", x, y, z)

    def refuse(self, kind: str, reason: str, amount: int = 1) -> None:
        """Count, log and say a refused ROS 2 goal; nothing is passed on."""
        self.node.count(f"refused.{kind}", amount)
        self.last_refusal = f"goal refused ({kind}): {reason}"
        self.node.warn(f"refused.{kind}", f"/goal_pose: {self.last_refusal}")
        self.publish_diagnostics()

    def shutdown(self) -> None:
        self.participant.close()


if __name__ == "__main__":
    run_component(Ros2Bridge)
