"""The state estimator: markers, wheel odometry and joint states in; the robot's state out.

The world frame is the reference marker F0 (eq. 6.2): a marker seen at x_i^c in the camera
frame is at x_i^0 = (x_0^c)^* x_i^c, with x_0^c low-pass filtered by eq. 6.1 over
``reference_samples`` samples, and the goal and obstacle markers over ``static_samples``.

The base pose (x, y, phi) is carried by wheel odometry: each ``base/odometry`` moves it by
the motion the odometry measured, in the base frame. A camera fix of the base marker F1 pulls
it towards the measured pose by 1/``base_samples`` (eq. 6.1 on the plane, the odometry
prediction standing for x_bar_{k-1}), at the time the frame was taken, the odometry since laid
on it again (``wbc.base_estimate``). Each odometry message yields one ``robot/state`` with
the newest arm joints and the end effector of the robot model: ``valid`` once the base has
had a fix; ``degraded`` while the base marker has not been seen for ``marker_timeout_s``.
When odometry stops for ``odometry_timeout_s`` as well, a 10 Hz timer publishes the state
as not valid.

A frame's markers are placed in F0 as they arrive, and published at once as
``world/markers`` (stamped with the frame's stamp: a lockstep simulator waits for them). The
frame is used from the first odometry stamped ``scene.camera.latency_s`` after it, in the
order the frames were taken: then the base is fixed, and ``control/goal`` and
``world/obstacles`` are published, stamped with that odometry's stamp (the time they are
known from), just before its state.
The goal is the pose x_d^0 = x_2^0 x_d^2 of eq. 6.3 with x_d^2 the scene's goal offset (its
translation for a ``position`` task), once the bin marker F2 has been seen; the obstacles, a
circle of the scene's radius at every obstacle marker (the controller adds the robot's radius,
section 5.5), its top as high as the marker lies, for every frame, seen or not, with the
planes and cylinders the scene declares (``scene.arm_obstacles``, already in F0). So what the
controller is given, and when, does not depend on when a frame's markers arrive within the
latency.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from components.joint_check import joints_match
from components.params import Param, ParamError
from components.process_entry import run_component
from components.pubsub import Input
from components.runtime import Component, Node
from messages import topics
from messages.base import IDENTITY_POSE
from messages.goal import Goal
from messages.joints import JointStates
from messages.markers import MarkerDetection, MarkerDetections
from messages.obstacles import Circle, Obstacles
from messages.odometry import BaseOdometry
from messages.state import RobotState
from profiles.scene import Scene
from wbc import dq
from wbc.base_estimate import BaseEstimate
from wbc.planar import compose, offset_pose, planar_of
from wbc.pose_filter import PoseFilter
from wbc.robot import MobileManipulator

WORLD_FRAME = "world"
TIMEOUT_CHECK_S = 0.1


@dataclass(frozen=True)
class Frame:
    """What one camera frame tells, ready to be used: the base pose F1 shows (None unseen),
    the goal pose x_d^0 (None before F2 is seen) and the obstacle circles, (x, y) in F0."""

    stamp_ns: int
    base: tuple[float, float, float] | None
    goal: np.ndarray | None
    obstacles: tuple[tuple[float, float], ...]


class StateEstimator(Component):
    """vision/markers, base/odometry and arm/joint_states in; robot/state, control/goal and
    world/obstacles out (see the module docstring)."""

    reads = (
        Input(topics.VISION_MARKERS, queue=30),
        Input(topics.BASE_ODOMETRY, queue=200),
        Input(topics.ARM_JOINT_STATES),
    )
    writes = (topics.ROBOT_STATE, topics.CONTROL_GOAL, topics.WORLD_OBSTACLES, topics.WORLD_MARKERS)
    params = (
        Param("task", str, "pose", choices=("pose", "position"), doc="the goal's task"),
        Param("reference_samples", int, 100, low=1, high=100000, doc="eq. 6.1 samples of F0"),
        Param(
            "static_samples",
            int,
            30,
            low=1,
            high=100000,
            doc="eq. 6.1 samples of the goal and obstacle markers",
        ),
        Param(
            "base_samples",
            int,
            20,
            low=1,
            high=1000,
            doc="a camera fix corrects the base by 1/base_samples",
        ),
        Param(
            "marker_timeout_s",
            float,
            0.5,
            low=0.01,
            high=60.0,
            doc="the state is degraded when F1 has not been seen for this long, s",
        ),
        Param(
            "odometry_timeout_s",
            float,
            0.5,
            low=0.01,
            high=60.0,
            doc="the state is invalid when odometry stopped this long too, s",
        ),
    )

    def __init__(self, node: Node) -> None:
        super().__init__(node)
        if node.profile.robot is None or node.profile.scene is None:
            raise ParamError("the state estimator needs the profile's `robot` and `scene`")
        self.robot = MobileManipulator.from_yaml(node.profile.robot)
        self.scene: Scene = node.profile.scene
        self.offset = offset_pose(*self.scene.goal.offset)
        p = node.params
        self.reference = PoseFilter(p["reference_samples"])
        self.statics: dict[int, PoseFilter] = {}
        self.base = BaseEstimate()
        self.frames: deque[Frame] = deque()
        self.latency_ns = round(self.scene.camera.latency_s * 1e9)
        self.fix_ns: int | None = None
        self.odometry_ns: int | None = None
        self.joints: tuple[float, ...] | None = None
        self.joints_ns = -1
        self.last_stamps: dict[str, int] = {}
        self.state = node.publisher(topics.ROBOT_STATE)
        self.goal = node.publisher(topics.CONTROL_GOAL)
        self.obstacles = node.publisher(topics.WORLD_OBSTACLES)
        self.placed = node.publisher(topics.WORLD_MARKERS)
        for name in (
            "base_fixes",
            "fixes_without_odometry",
            "duplicates",
            "degraded_states",
            "joints_behind",
            "refused_joint_states",
        ):
            node.counters[name] = 0
        node.subscribe(topics.VISION_MARKERS, self.on_markers)
        node.subscribe(topics.BASE_ODOMETRY, self.on_odometry)
        node.subscribe(topics.ARM_JOINT_STATES, self.on_joints)
        node.timer(TIMEOUT_CHECK_S, self.check_inputs)

    def _fresh(self, name: str, stamp_ns: int) -> bool:
        """False for a message not newer than the last of its topic (a repeat, counted)."""
        if stamp_ns <= self.last_stamps.get(name, -1):
            self.node.count("duplicates")
            return False
        self.last_stamps[name] = stamp_ns
        return True

    # -- the camera ------------------------------------------------------------------------

    def on_markers(self, message: MarkerDetections) -> None:
        """Filter F0, place every other marker in F0 (eq. 6.2) and publish them; keep what the
        frame tells until its time comes (``use_frames``)."""
        stamp = message.header.stamp_ns
        if not self._fresh("markers", stamp):
            return
        seen = {m.id: np.array(m.pose) for m in message.markers}
        scene = self.scene
        if scene.reference.id in seen:
            self.reference.update(seen[scene.reference.id])
        x0c = self.reference.pose
        in_world = {}
        if x0c is not None:
            in_world = {i: dq.normalize(dq.mul(dq.conj(x0c), p)) for i, p in seen.items()}
            for marker_id in (scene.goal.id, *scene.obstacles.ids):
                if marker_id in in_world:
                    self._static(marker_id).update(in_world[marker_id])
        base = in_world.get(scene.base.id)
        self.frames.append(
            Frame(
                stamp,
                None if base is None else self._base_of(base),
                self._goal_pose(),
                self._obstacle_centres(),
            )
        )
        self.placed.put(
            MarkerDetections(
                header=self.node.header(WORLD_FRAME, stamp, self.placed.next_seq),
                markers=tuple(
                    MarkerDetection(
                        id=m.id,
                        pose=tuple(in_world[m.id].tolist()),
                        reprojection_error=m.reprojection_error,
                    )
                    for m in message.markers
                    if m.id in in_world
                ),
            )
        )

    def _static(self, marker_id: int) -> PoseFilter:
        if marker_id not in self.statics:
            self.statics[marker_id] = PoseFilter(self.node.params["static_samples"])
        return self.statics[marker_id]

    def _base_of(self, marker_pose: np.ndarray) -> tuple[float, float, float]:
        """The base pose the F1 marker shows: its planar pose, its offset undone."""
        ox, oy = self.scene.base.offset
        return compose(planar_of(marker_pose), (-ox, -oy, 0.0))

    def _goal_pose(self) -> np.ndarray | None:
        bin_marker = self.statics.get(self.scene.goal.id)
        if bin_marker is None or bin_marker.pose is None:
            return None
        return dq.normalize(dq.mul(bin_marker.pose, self.offset))

    def _obstacle_centres(self) -> tuple[tuple[float, float], ...]:
        centres = []
        for marker_id in self.scene.obstacles.ids:
            marker = self.statics.get(marker_id)
            if marker is not None and marker.pose is not None:
                centres.append(planar_of(marker.pose)[:2])
        return tuple(centres)

    def use_frames(self, stamp_ns: int) -> None:
        """Use every frame taken ``latency_s`` or more before ``stamp_ns``, oldest first: fix
        the base at the frame's time, publish its goal and obstacles."""
        while self.frames and self.frames[0].stamp_ns + self.latency_ns <= stamp_ns:
            frame = self.frames.popleft()
            if frame.base is not None:
                gain = 1.0 / self.node.params["base_samples"]
                if self.base.fix(frame.stamp_ns, frame.base, gain):
                    self.fix_ns = frame.stamp_ns
                    self.node.count("base_fixes")
                else:
                    self.node.count("fixes_without_odometry")
            self._publish_goal(frame, stamp_ns)
            self._publish_obstacles(frame, stamp_ns)

    def _publish_goal(self, frame: Frame, stamp_ns: int) -> None:
        if frame.goal is None:
            return
        header = self.node.header(WORLD_FRAME, stamp_ns, self.goal.next_seq)
        if self.node.params["task"] == "pose":
            goal = Goal(header=header, task="pose", pose=tuple(frame.goal.tolist()))
        else:
            goal = Goal(
                header=header,
                task="position",
                position=tuple(dq.translation(frame.goal)[1:].tolist()),
            )
        self.goal.put(goal)

    def _publish_obstacles(self, frame: Frame, stamp_ns: int) -> None:
        radius, height = self.scene.obstacles.radius_m, self.scene.obstacles.height_m or None
        circles = tuple(Circle(x=x, y=y, radius=radius, height=height) for x, y in frame.obstacles)
        header = self.node.header(WORLD_FRAME, stamp_ns, self.obstacles.next_seq)
        self.obstacles.put(
            Obstacles(header=header, circles=circles, solids=self.scene.arm_obstacles)
        )

    # -- odometry and joints ---------------------------------------------------------------

    def on_joints(self, message: JointStates) -> None:
        """Keep the newest joints; joints that are not the robot's are refused
        (``refused_joint_states``)."""
        names = self.robot.joint_names
        if not joints_match(
            self.node, "refused_joint_states", "arm/joint_states", message.names, names
        ):
            return
        self.joints = tuple(message.positions)
        self.joints_ns = message.header.stamp_ns

    def on_odometry(self, message: BaseOdometry) -> None:
        """Move the base as the odometry says, use the frames whose time has come, publish
        the state."""
        stamp = message.header.stamp_ns
        if not self._fresh("odometry", stamp):
            return
        if self.joints_ns < stamp:
            self.node.count("joints_behind")
        self.base.move(stamp, (message.x, message.y, message.phi))
        self.odometry_ns = stamp
        self.use_frames(stamp)
        self.publish_state(stamp)

    def publish_state(self, stamp_ns: int) -> None:
        """One robot/state from the base estimate and the newest joints."""
        pose = self.base.pose
        valid = pose is not None and self.joints is not None
        age_s = (stamp_ns - self.fix_ns) / 1e9 if self.fix_ns is not None else 0.0
        degraded = valid and age_s > self.node.params["marker_timeout_s"]
        if degraded:
            self.node.count("degraded_states")
        base = pose if pose is not None else (0.0, 0.0, 0.0)
        joints = self.joints if self.joints is not None else (0.0,) * self.robot.arm_dof
        q = np.array([*base, *joints])
        end_effector = tuple(self.robot.fkm(q).tolist()) if valid else IDENTITY_POSE
        self.state.put(
            RobotState(
                header=self.node.header(WORLD_FRAME, stamp_ns, self.state.next_seq),
                base_pose=base,
                arm_joints=joints,
                joint_names=self.robot.joint_names,
                end_effector=end_effector,
                valid=valid,
                age_s=max(age_s, 0.0),
                degraded=degraded,
            )
        )

    def check_inputs(self) -> None:
        """Timer: with odometry silent and the marker lost as well, say the state is invalid."""
        now = self.node.clock.now_ns()
        p = self.node.params
        odometry_silent = (
            self.odometry_ns is None or now - self.odometry_ns > p["odometry_timeout_s"] * 1e9
        )
        marker_lost = self.fix_ns is None or now - self.fix_ns > p["marker_timeout_s"] * 1e9
        if odometry_silent and marker_lost:
            self.base.reset()  # a fix is needed again
        if odometry_silent:
            self.use_frames(now)  # the camera's frames are still used, on the clock's time
        if odometry_silent and self.odometry_ns is not None:
            self.publish_state(now)


if __name__ == "__main__":
    run_component(StateEstimator)
