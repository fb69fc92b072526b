"""The state estimator: markers, wheel odometry and joint states in; the robot's state out.

The world frame is the reference marker F0 (eq. 6.2): a marker seen at x_i^c in the camera
frame is at x_i^0 = (x_0^c)^* x_i^c, with x_0^c low-pass filtered by eq. 6.1 over
``reference_samples`` samples, and the goal and obstacle markers over ``static_samples``.

The base pose (x, y, phi) is carried by wheel odometry: each ``base/odometry`` moves it by
the motion the odometry measured, in the base frame. A camera fix of the base marker F1 pulls
it towards the measured pose by 1/``base_samples`` (eq. 6.1 on the plane, the odometry
prediction standing for x_bar_{k-1}). Each odometry message yields one ``robot/state`` with
the newest arm joints and the end effector of the robot model: ``valid`` once the base has
had a fix; ``degraded`` while the base marker has not been seen for ``marker_timeout_s``.
When odometry stops for ``odometry_timeout_s`` as well, a 10 Hz timer publishes the state
as not valid.

Each processed frame also yields ``control/goal``, the pose x_d^0 = x_2^0 x_d^2 of eq. 6.3
with x_d^2 the scene's goal offset (its translation for a ``position`` task), once the bin
marker F2 has been seen, then ``world/obstacles``: a circle of the scene's radius at every
obstacle marker (the controller adds the robot's radius, section 5.5). Both carry the
frame's stamp; the obstacles are published for every frame, seen or not (the simulator's
lockstep waits for them).
"""

from __future__ import annotations

import math

import numpy as np

from components.params import Param, ParamError
from components.process_entry import run_component
from components.pubsub import Input
from components.runtime import Component, Node
from messages import topics
from messages.base import ARM_JOINTS, IDENTITY_POSE
from messages.goal import Goal
from messages.joints import JointStates
from messages.markers import MarkerDetections
from messages.obstacles import Circle, Obstacles
from messages.odometry import BaseOdometry
from messages.state import RobotState
from profiles.scene import Scene
from wbc import dq
from wbc.planar import offset_pose, planar_of, wrap
from wbc.pose_filter import PoseFilter
from wbc.robot import MobileManipulator

WORLD_FRAME = "world"
TIMEOUT_CHECK_S = 0.1


class StateEstimator(Component):
    """vision/markers, base/odometry and arm/joint_states in; robot/state, control/goal and
    world/obstacles out (see the module docstring)."""

    reads = (
        Input(topics.VISION_MARKERS, queue=30),
        Input(topics.BASE_ODOMETRY, queue=200),
        Input(topics.ARM_JOINT_STATES),
    )
    writes = (topics.ROBOT_STATE, topics.CONTROL_GOAL, topics.WORLD_OBSTACLES)
    params = (
        Param("task", str, "pose", choices=("pose", "position"), doc="the goal's task"),
        Param("reference_samples", int, 100, low=1, high=100000, doc="eq. 6.1 samples of F0"),
        Param("static_samples", int, 30, low=1, high=100000,
              doc="eq. 6.1 samples of the goal and obstacle markers"),
        Param("base_samples", int, 20, low=1, high=1000,
              doc="a camera fix corrects the base by 1/base_samples"),
        Param("marker_timeout_s", float, 0.5, low=0.01, high=60.0,
              doc="the state is degraded when F1 has not been seen for this long, s"),
        Param("odometry_timeout_s", float, 0.5, low=0.01, high=60.0,
              doc="the state is invalid when odometry stopped this long too, s"),
    )  # fmt: skip

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
        self.base: tuple[float, float, float] | None = None
        self.fix_ns: int | None = None
        self.odometry: tuple[float, float, float] | None = None
        self.odometry_ns: int | None = None
        self.joints: tuple[float, ...] | None = None
        self.joints_ns = -1
        self.last_stamps: dict[str, int] = {}
        self.state = node.publisher(topics.ROBOT_STATE)
        self.goal = node.publisher(topics.CONTROL_GOAL)
        self.obstacles = node.publisher(topics.WORLD_OBSTACLES)
        for name in ("base_fixes", "duplicates", "degraded_states", "joints_behind"):
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
        """Filter F0, place every other marker in F0 (eq. 6.2), correct the base, publish the
        goal and the obstacles."""
        stamp = message.header.stamp_ns
        if not self._fresh("markers", stamp):
            return
        seen = {m.id: np.array(m.pose) for m in message.markers}
        scene = self.scene
        if scene.reference.id in seen:
            self.reference.update(seen[scene.reference.id])
        x0c = self.reference.pose
        if x0c is not None:
            in_world = {i: dq.normalize(dq.mul(dq.conj(x0c), p)) for i, p in seen.items()}
            if scene.base.id in in_world:
                self._correct_base(in_world[scene.base.id], stamp)
            for marker_id in (scene.goal.id, *scene.obstacles.ids):
                if marker_id in in_world:
                    self._static(marker_id).update(in_world[marker_id])
        self._publish_goal(stamp)
        self._publish_obstacles(stamp)

    def _static(self, marker_id: int) -> PoseFilter:
        if marker_id not in self.statics:
            self.statics[marker_id] = PoseFilter(self.node.params["static_samples"])
        return self.statics[marker_id]

    def _correct_base(self, marker_pose: np.ndarray, stamp_ns: int) -> None:
        """The base pose the F1 marker shows (its offset undone), blended in by 1/base_samples."""
        mx, my, mphi = planar_of(marker_pose)
        ox, oy = self.scene.base.offset
        c, s = math.cos(mphi), math.sin(mphi)
        fix = (mx - c * ox + s * oy, my - s * ox - c * oy, mphi)
        if self.base is None:
            self.base = fix
        else:
            x, y, phi = self.base
            gain = 1.0 / self.node.params["base_samples"]
            self.base = (x + gain * (fix[0] - x), y + gain * (fix[1] - y),
                         phi + gain * wrap(fix[2] - phi))  # fmt: skip
        self.fix_ns = stamp_ns
        self.node.count("base_fixes")

    def _publish_goal(self, stamp_ns: int) -> None:
        bin_marker = self.statics.get(self.scene.goal.id)
        if bin_marker is None or bin_marker.pose is None:
            return
        desired = dq.normalize(dq.mul(bin_marker.pose, self.offset))
        header = self.node.header(WORLD_FRAME, stamp_ns, self.goal.next_seq)
        if self.node.params["task"] == "pose":
            goal = Goal(header=header, task="pose", pose=tuple(desired.tolist()))
        else:
            goal = Goal(header=header, task="position",
                        position=tuple(dq.translation(desired)[1:].tolist()))  # fmt: skip
        self.goal.put(goal)

    def _publish_obstacles(self, stamp_ns: int) -> None:
        circles = []
        for marker_id in self.scene.obstacles.ids:
            marker = self.statics.get(marker_id)
            if marker is not None and marker.pose is not None:
                x, y, _ = planar_of(marker.pose)
                circles.append(Circle(x=x, y=y, radius=self.scene.obstacles.radius_m))
        header = self.node.header(WORLD_FRAME, stamp_ns, self.obstacles.next_seq)
        self.obstacles.put(Obstacles(header=header, circles=tuple(circles)))

    # -- odometry and joints ---------------------------------------------------------------

    def on_joints(self, message: JointStates) -> None:
        if len(message.positions) != ARM_JOINTS:
            raise ValueError(f"expected {ARM_JOINTS} joints, got {len(message.positions)}")
        self.joints = tuple(message.positions)
        self.joints_ns = message.header.stamp_ns

    def on_odometry(self, message: BaseOdometry) -> None:
        """Move the base by the odometry's motion in the base frame; publish the state."""
        stamp = message.header.stamp_ns
        if not self._fresh("odometry", stamp):
            return
        if self.joints_ns < stamp:
            self.node.count("joints_behind")
        current = (message.x, message.y, message.phi)
        if self.odometry is not None and self.base is not None:
            ox, oy, ophi = self.odometry
            c, s = math.cos(ophi), math.sin(ophi)
            forward = c * (current[0] - ox) + s * (current[1] - oy)
            lateral = -s * (current[0] - ox) + c * (current[1] - oy)
            x, y, phi = self.base
            c, s = math.cos(phi), math.sin(phi)
            self.base = (x + c * forward - s * lateral, y + s * forward + c * lateral,
                         phi + (current[2] - ophi))  # fmt: skip
        self.odometry, self.odometry_ns = current, stamp
        self.publish_state(stamp)

    def publish_state(self, stamp_ns: int) -> None:
        """One robot/state from the base estimate and the newest joints."""
        valid = self.base is not None and self.joints is not None
        age_s = (stamp_ns - self.fix_ns) / 1e9 if self.fix_ns is not None else 0.0
        degraded = valid and age_s > self.node.params["marker_timeout_s"]
        if degraded:
            self.node.count("degraded_states")
        base = self.base if self.base is not None else (0.0, 0.0, 0.0)
        joints = self.joints if self.joints is not None else (0.0,) * ARM_JOINTS
        q = np.array([*base, *joints])
        end_effector = tuple(self.robot.fkm(q).tolist()) if valid else IDENTITY_POSE
        self.state.put(
            RobotState(
                header=self.node.header(WORLD_FRAME, stamp_ns, self.state.next_seq),
                base_pose=base,
                arm_joints=joints,
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
        odometry_silent = self.odometry_ns is None or now - self.odometry_ns > p[
            "odometry_timeout_s"] * 1e9  # fmt: skip
        marker_lost = self.fix_ns is None or now - self.fix_ns > p["marker_timeout_s"] * 1e9
        if odometry_silent and marker_lost and self.base is not None:
            self.base = None  # a fix is needed again
        if odometry_silent and self.odometry_ns is not None:
            self.publish_state(now)


if __name__ == "__main__":
    run_component(StateEstimator)
