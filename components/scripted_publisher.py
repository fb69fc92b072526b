"""A tool that publishes a fixed robot state and goal from its parameters, at a rate.

It stands in for the estimator and the operator when a controller is tested or
demonstrated alone. The state is ``(base_x, base_y, base_phi)`` and the arm joints
``joints`` (one per joint of the profile's robot, named as its description names them), or
Little John's five ``q1..q5`` when ``joints`` is empty; its end effector is left at
``IDENTITY_POSE`` (a consumer computes kinematics from the configuration). A state of another
size than the robot's is not published (``refused_states``, one line naming the joints). The
goal is a position ``(goal_x, goal_y, goal_z)``, or with ``goal_task: pose`` the pose at that
position rotated ``goal_yaw`` about the world z axis, unless ``goal_pose`` gives the
whole pose as a list of eight numbers (a unit dual quaternion). Parameters changed
with ``parsimony param set`` apply from the next message (``rate_hz`` from the next period).
"""

from __future__ import annotations

from components.params import Param, load_robot
from components.process_entry import run_component
from components.robot_vector import RobotVector
from components.runtime import Component, Node
from messages import topics
from messages.base import IDENTITY_POSE, default_joint_names
from messages.goal import Goal
from messages.state import RobotState
from wbc import dq

WORLD_FRAME = "world"


class ScriptedPublisher(Component):
    """Publishes ``robot/state`` and ``control/goal`` from parameters every ``1 / rate_hz`` s."""

    writes = (topics.ROBOT_STATE, topics.CONTROL_GOAL)

    params = (
        Param("rate_hz", float, 10.0, low=0.1, high=1000.0, doc="publishing rate"),
        Param("base_x", float, 0.0, doc="base position x, m"),
        Param("base_y", float, 0.0, doc="base position y, m"),
        Param("base_phi", float, 0.0, doc="base heading, rad"),
        *(Param(f"q{i}", float, 0.0, doc=f"arm joint {i}, rad") for i in range(1, 6)),
        RobotVector(
            "joints",
            tuple,
            (),
            optional=True,
            doc="a position per arm joint of the robot, rad or m; [] takes q1..q5",
        ),
        Param("goal_task", str, "position", choices=("position", "pose"), doc="task kind"),
        Param("goal_x", float, 1.0, doc="goal position x, m"),
        Param("goal_y", float, 0.0, doc="goal position y, m"),
        Param("goal_z", float, 0.5, doc="goal position z, m"),
        Param("goal_yaw", float, 0.0, doc="goal rotation about z for a pose task, rad"),
        Param(
            "goal_pose",
            tuple,
            (),
            length=8,
            optional=True,
            doc="the pose task's goal: 8 numbers, a unit dual quaternion; [] for none",
        ),
    )

    def __init__(self, node: Node) -> None:
        super().__init__(node)
        robot = node.profile.robot
        self.names = load_robot(robot).joint_names if robot is not None else None
        """The robot's joint names (None without a robot: q1..qn)."""
        node.counters["refused_states"] = 0
        self.state = node.publisher(topics.ROBOT_STATE)
        self.goal = node.publisher(topics.CONTROL_GOAL)
        self.timer = node.timer(1.0 / float(node.params["rate_hz"]), self.publish)

    def publish(self) -> None:
        """Publish one state and one goal from the current parameters."""
        p = self.node.params
        self.timer.period_ns = round(1e9 / float(p["rate_hz"]))
        header = self.node.header(WORLD_FRAME)
        joints = p["joints"] or tuple(p[f"q{i}"] for i in range(1, 6))
        names = self.names or default_joint_names(len(joints))
        if len(joints) == len(names):
            self.state.put(
                RobotState(
                    header=header,
                    base_pose=(p["base_x"], p["base_y"], p["base_phi"]),
                    arm_joints=joints,
                    joint_names=names,
                    end_effector=IDENTITY_POSE,
                    valid=True,
                    age_s=0.0,
                )
            )
        else:
            self.node.count("refused_states")
            self.node.warn(
                "refused_states",
                f"joints: {len(joints)} given, the robot's are {len(names)} ({', '.join(names)});"
                " no state published",
            )
        position = (p["goal_x"], p["goal_y"], p["goal_z"])
        if p["goal_task"] == "pose" and p["goal_pose"]:
            self.goal.put(Goal(header=header, task="pose", pose=p["goal_pose"]))
        elif p["goal_task"] == "pose":
            rotation = dq.rotation_quaternion(float(p["goal_yaw"]), [0.0, 0.0, 1.0])
            pose = tuple(float(v) for v in dq.pose(rotation, position))
            self.goal.put(Goal(header=header, task="pose", pose=pose))
        else:
            self.goal.put(Goal(header=header, task="position", position=position))


if __name__ == "__main__":
    run_component(ScriptedPublisher)
