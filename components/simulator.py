"""The 2D simulator as a process: the pymunk world of ``sim2d.world`` and its ceiling camera.

It consumes ``base/command`` and ``arm/command`` and publishes what the drivers and the
camera publish on the real robot, every ``step_s`` of simulated time::

    sim/clock          t
    arm/joint_states   the servo angles and speeds
    base/odometry      the wheel encoder counts (noise and slip from the parameters), the
                       distances and the dead-reckoned pose from them, as the Create driver does
    camera/image       a 640x480 grey frame of the scene's markers at the camera's rate, as a
                       JPEG of ``jpeg_quality`` (as a UVC camera's MJPEG stream) or raw mono8
    sim/truth          the real pose, joints, end effector, contacts and the arm's penetrations
                       into the scene's solids in 3-D (tests and reports only)

They are published by ``components.sim_outputs`` (the readings made by
``components.sim_sensors``, the frames by ``components.sim_camera``).
The robot is the profile's ``robot:`` description: its joints (any number, revolute or
prismatic, named as the description names them) and its base, driven by the wheel speeds of
``base/command`` when differential, by its forward, lateral and angular velocities when
omnidirectional, never moved when fixed. An ``arm/command`` whose joints are not the robot's
is refused (``refused_arm_commands``, one line naming the joints expected).

It stops the robot when no command has arrived for ``command_timeout_s`` of simulated time.
A ``start`` with a part of the robot inside one of the scene's solids is warned of, one line
per solid naming it and saying what the robot will do (``wbc.geometry.start_inside``).

Time: ``real_time_factor`` 1 runs as fast as the wall clock, 2 twice as fast, 0 as fast as it
can. With ``lockstep`` each step waits until the loop has answered it, acknowledged by stamps:
the sensors of t by ``base/command`` and ``arm/command`` stamped t (the controller answers the
state of t with commands of t), and a camera frame stamped t by ``vision/markers`` (the
tracker) and ``world/markers`` (the estimator) stamped t, before the sensors of
t + ``scene.camera.latency_s`` (when the estimator uses the frame) and before the next frame,
whichever comes first: the tracker works on a frame while the loop runs on, and a frame is
never replaced by the next before it is answered. Frames are drawn on a thread of their own,
while the loop answers the sensors of the same step (published first when the latency is a
step or more). Only then does t advance, so a run does not
depend on the machine's load. An answer missing for ``ack_timeout_s`` host seconds is counted
(``lockstep_timeouts``) and the step goes on; one owed since before a component of the
namespace restarted (its liveliness token dropped and came back: the new process never saw what
it would answer) is given up sooner, ``lockstep_gate.RESTART_GRACE_S`` after the restart; the
waiting itself is the lockstep gate's (``components.lockstep_gate``). The simulator starts when
``paused`` is set false (a profile may start it so).
"""

from __future__ import annotations

import time

import numpy as np
import zenoh

from components.joint_check import joints_match
from components.lockstep_gate import COMMANDS, FRAME_ANSWERS, Awaited, LockstepGate
from components.params import Param, ParamError
from components.process_entry import run_component
from components.pubsub import Input
from components.robot_vector import RobotVector, of_robot
from components.runtime import Component, Node
from components.sim_outputs import SimOutputs
from components.stop_latch import StopLatch
from messages import topics
from messages.clock import Clock
from messages.commands import ArmCommand, BaseCommand
from messages.stop import StopState
from profiles.scene import Scene
from sim2d.scenarios import SEED_MAX
from sim2d.world import World, WorldSettings
from wbc.geometry.obstacles import Circle
from wbc.geometry.start_inside import inside_at_start
from wbc.robot import BASE_DOF, MobileManipulator

LOCKSTEP_CHECK_S = 0.05
"""How often the simulator looks for an answer that is overdue (host seconds)."""
PAUSED_CLOCK_S = 0.1
"""How often a paused simulator publishes its clock (host seconds)."""


def start_of(robot: MobileManipulator, start: tuple[float, ...]) -> np.ndarray:
    """q0 from the ``start`` parameter: the whole configuration, or the base's pose alone with
    every joint at 0 (or its nearest limit)."""
    if len(start) == BASE_DOF:
        return np.concatenate((start, np.clip(0.0, robot.q_min[BASE_DOF:], robot.q_max[BASE_DOF:])))
    names = ", ".join(robot.joint_names)
    return np.array(of_robot("start", start, robot.dof, f"x, y, phi, {names}; or x, y, phi"))


class Simulator(Component):
    """sim2d: world, encoders, servos and ceiling camera (see the module docstring)."""

    reads = (
        Input(topics.BASE_COMMAND),
        Input(topics.ARM_COMMAND),
        Input(topics.VISION_MARKERS),
        Input(topics.WORLD_MARKERS),
    )
    writes = (
        topics.SIM_CLOCK,
        topics.ARM_JOINT_STATES,
        topics.BASE_ODOMETRY,
        topics.CAMERA_IMAGE,
        topics.SIM_TRUTH,
    )
    params = (
        Param("step_s", float, 0.01, low=1e-4, high=0.1, doc="simulated time per step, s"),
        Param(
            "real_time_factor",
            float,
            1.0,
            low=0.0,
            high=1000.0,
            doc="simulated s per wall s; 0: as fast as possible",
        ),
        Param("lockstep", bool, False, doc="advance only when the loop answered each step"),
        Param(
            "ack_timeout_s",
            float,
            2.0,
            low=0.01,
            high=60.0,
            doc="host s a lockstep step waits for an answer",
        ),
        Param("paused", bool, False, doc="hold the simulation (set false to start)"),
        Param(
            "command_timeout_s",
            float,
            0.5,
            low=0.01,
            high=10.0,
            doc="stop the robot after this long without a command, s (simulated)",
        ),
        Param("seed", int, 0, low=0, high=SEED_MAX, doc="noise seed"),
        RobotVector(
            "start",
            tuple,
            (0.0, 0.0, 0.0, 0.0, -0.2, 0.2, 0.0, 0.5),
            least=3,
            doc="q0 = [x, y, phi, a position per arm joint]; [x, y, phi]: every joint at 0 "
            "(or its nearest limit)",
        ),
        Param("obstacles", list, (), length=3, doc="obstacle circles [[x, y, radius], ...], m"),
        Param(
            "goal_marker", tuple, (0.6, 0.0, 0.0), length=3, doc="the bin marker F2: [x, y, yaw]"
        ),
        Param(
            "hide_base_marker",
            list,
            (),
            length=2,
            doc="sim seconds [[from, to], ...] the base marker is hidden",
        ),
        Param(
            "host_epoch",
            bool,
            False,
            doc="stamp with the host's clock, to match drivers on host time (real time)",
        ),
        Param("camera", bool, True, doc="render camera frames"),
        Param("image_noise", float, 2.0, low=0.0, high=50.0, doc="pixel noise std, grey levels"),
        Param("image_blur_px", float, 0.6, low=0.0, high=5.0, doc="Gaussian blur sigma, px"),
        Param(
            "image_format",
            str,
            "jpeg",
            choices=("jpeg", "mono8"),
            doc="camera frames as JPEG files or raw grey pixels",
        ),
        Param("jpeg_quality", int, 90, low=1, high=100, doc="JPEG quality of the frames"),
        Param(
            "encoder_noise_counts",
            float,
            0.0,
            low=0.0,
            high=100.0,
            doc="encoder noise std per step, counts",
        ),
        Param("wheel_slip", float, 0.0, low=0.0, high=0.5, doc="wheel slip std, fraction"),
        Param("wheel_acceleration_max", float, 1.0, low=0.01, high=100.0, doc="m/s^2"),
    )

    def __init__(self, node: Node) -> None:
        super().__init__(node)
        p = node.params
        if node.profile.robot is None:
            raise ParamError("the simulator needs the profile's `robot`")
        if node.profile.scene is None:
            raise ParamError("the simulator needs the profile's `scene` (markers and camera)")
        self.robot = MobileManipulator.from_yaml(node.profile.robot)
        self.scene: Scene = node.profile.scene
        self.obstacles = [Circle(*c) for c in p["obstacles"]]
        # The scene declares its solids in F0; this world has F0 at the reference pose.
        solids = tuple(
            solid.moved(*self.scene.reference_pose) for solid in self.scene.arm_obstacles.solids()
        )
        settings = WorldSettings(
            wheel_acceleration_max=p["wheel_acceleration_max"],
            encoder_noise_counts=p["encoder_noise_counts"],
            wheel_slip=p["wheel_slip"],
        )
        start = start_of(self.robot, p["start"])
        for index, line in enumerate(
            inside_at_start(self.robot, start, solids, self.scene.solid_labels())
        ):
            node.warn(f"starts_inside.{index}", line)
        self.world = World(
            self.robot, start, self.obstacles, settings, seed=p["seed"], solids=solids
        )
        self.step_ns = round(p["step_s"] * 1e9)
        self.now_ns = time.time_ns() if p["host_epoch"] else 0
        self.last_command_ns: int | None = None
        self.gate = LockstepGate(
            node.counters,
            round(self.scene.camera.latency_s * 1e9),
            lambda: node.params["ack_timeout_s"],
        )
        self.outputs = SimOutputs(
            node,
            self.writes,
            self.world,
            self.robot,
            self.scene,
            self.obstacles,
            solids,
            settings.counts_per_turn,
            self.now_ns,
        )
        self.frame_done = True
        node.counters["refused_arm_commands"] = 0
        commanded = {i.topic.name for i in self.reads} & set(COMMANDS)
        self.latch = StopLatch(node, self.on_stop) if commanded else None
        """The emergency stop, when it reads commands (an emulated robot takes them from its
        drivers, which hold it, as the real robot does)."""
        for topic in self.reads:
            node.subscribe(topic.topic, self._answer_handler(topic.topic.name))
        self.base_command = self.arm_command = None
        self._queued = False
        if p["real_time_factor"] > 0:
            node.timer(p["step_s"] / p["real_time_factor"], self._paced_tick)
        node.timer(LOCKSTEP_CHECK_S, self._check_overdue)
        node.timer(PAUSED_CLOCK_S, self._paused_clock)
        self._gone: set[str] = set()
        """Components whose liveliness token dropped and has not come back."""
        self._tokens = node.session.liveliness().declare_subscriber(
            topics.liveliness_selector(node.namespace), self._on_token, history=True
        )

    # -- the loop -------------------------------------------------------------------------

    def _paused_clock(self) -> None:
        """While paused, publish the clock where it stands, marked paused: the components on
        simulated time do not take the held time for a stalled simulator, and whoever starts
        the run can see that every reader of the simulator's topics is reached before the first
        step (a reader reached only later misses the first camera frame)."""
        if self.node.params["paused"]:
            self.outputs.put(topics.SIM_CLOCK, Clock(stamp_ns=self.now_ns, paused=True))

    def _paced_tick(self) -> None:
        """Timer at the real-time factor's pace: step unless paused or an answer is awaited."""
        if not self.gate.waiting and not self.node.params["paused"]:
            self.step()

    def _kick(self) -> None:
        """As fast as possible (factor 0): queue the next step unless one is queued, the
        simulation is paused or an answer is awaited."""
        p = self.node.params
        if p["real_time_factor"] or p["paused"] or self.gate.waiting or self._queued:
            return
        self._queued = True
        self.node.post(self._free_tick)

    def _free_tick(self) -> None:
        """One step, then the next after the events already waiting (commands, queries)."""
        self._queued = False
        if not self.gate.waiting and not self.node.params["paused"]:
            self.step()
        self._kick()

    def step(self) -> None:
        """Advance one step; publish the clock, the camera frame when one is due, the sensors."""
        self._apply_commands()
        self.world.step(self.step_ns / 1e9)
        # On host time the stamps are the host's: the paced steps lag it under load.
        host = self.node.params["host_epoch"]
        self.now_ns = time.time_ns() if host else self.now_ns + self.step_ns
        clock = Clock(stamp_ns=self.now_ns, lockstep=self.node.params["lockstep"])
        self.outputs.put(topics.SIM_CLOCK, clock)
        self.frame_done = not self.outputs.frame_due(self.now_ns)
        self._go_on()

    def _go_on(self) -> None:
        """The rest of a step, each part once the answers it needs are in (lockstep): the
        sensors (after the answers of a frame whose latency has passed), the frame due (after
        the last frame's answers), then the wait for the commands. When the latency is a step
        or more, the sensors go first, so the loop runs while the frame is drawn."""
        gate, lockstep = self.gate, self.node.params["lockstep"]
        if gate.frame_due(self.now_ns):
            return
        if gate.latency_ns >= self.step_ns:
            self.outputs.sensors_of(self.now_ns)
        if not self.frame_done:
            if gate.frame_pending():
                return
            self.frame_done = True
            self.outputs.frame(self.now_ns, lockstep)
            if lockstep:
                gate.frame_taken(self.now_ns)
                if gate.latency_ns == 0:
                    return gate.wait(FRAME_ANSWERS, self.now_ns)
        self.outputs.sensors_of(self.now_ns)
        if lockstep:
            gate.wait(COMMANDS, self.now_ns)
            self._proceed(gate.check())  # the commands may be in already

    def _answer_handler(self, name: str):
        def on_answer(message) -> None:
            if name in COMMANDS:
                self._take_command(name, message)
            self._proceed(self.gate.note(name, message.header.stamp_ns))

        return on_answer

    def _proceed(self, done: Awaited | None) -> None:
        """A wait is over (answered or overdue): go on with the step or the next one."""
        if done is None:
            return
        if done.frame:
            self._go_on()
        self._kick()

    def _check_overdue(self) -> None:
        overdue = self.gate.overdue()
        if overdue is not None:
            awaited, missing, restarted = overdue
            why = f" ({restarted} restarted)" if restarted else ""
            self.node.warn(
                "lockstep_timeouts",
                f"no answer on {', '.join(missing)} for t={awaited.stamp_ns / 1e9:.3f} s{why}; "
                "going on",
            )
            self._proceed(awaited)
        self._kick()  # also starts a run once ``paused`` is set false

    def _on_token(self, sample: zenoh.Sample) -> None:
        """Zenoh thread: a component's liveliness token declared or dropped, handed on."""
        name = topics.component_of_liveliness_key(self.node.namespace, str(sample.key_expr))
        alive = sample.kind == zenoh.SampleKind.PUT
        self.node.post(lambda: self._token(name, alive))

    def _token(self, name: str, alive: bool) -> None:
        """A component's token dropped, or came back: the component restarted, and what the
        lockstep gate awaits now is forsaken (the new process never saw it)."""
        if not alive:
            self._gone.add(name)
        elif name in self._gone:
            self._gone.discard(name)
            self.gate.forsake(name)

    # -- commands in ----------------------------------------------------------------------

    def _take_command(self, name: str, message: BaseCommand | ArmCommand) -> None:
        """Hold a command until the next; an arm command whose joints are not the robot's is
        refused (``refused_arm_commands``): the last one holds, until its timeout. While stopped
        every command is refused (``refused_while_stopped``)."""
        if self.latch is not None and self.latch.refuses():
            return
        if name == COMMANDS[0]:
            self.base_command = message
        elif joints_match(
            self.node,
            "refused_arm_commands",
            "arm/command",
            message.joint_names,
            self.robot.joint_names,
        ):
            self.arm_command = message
        else:
            return
        self.last_command_ns = self.now_ns

    def on_stop(self, state: StopState) -> None:
        """The emergency stop (``components.stop_latch``): the commands held are dropped, the
        robot stopped from the next step on."""
        if state.stopped:
            self.base_command = self.arm_command = self.last_command_ns = None

    def _apply_commands(self) -> None:
        timeout_ns = self.node.params["command_timeout_s"] * 1e9
        if (
            (self.latch is not None and self.latch.stopped)
            or self.last_command_ns is None
            or self.now_ns - self.last_command_ns > timeout_ns
        ):
            self.world.stop()
            return
        base, arm = self.base_command, self.arm_command
        joints = arm.joint_velocities if arm else (0.0,) * self.robot.arm_dof
        if self.robot.base.kind == "differential":
            left, right = (base.left_wheel, base.right_wheel) if base else (0.0, 0.0)
            self.world.command(left, right, joints)
        elif base is None:
            self.world.drive(0.0, 0.0, 0.0, joints)
        else:
            velocity = (base.forward_velocity, base.lateral_velocity, base.angular_velocity)
            self.world.drive(*velocity, joints)

    def shutdown(self) -> None:
        self._tokens.undeclare()
        self.outputs.shutdown()


if __name__ == "__main__":
    run_component(Simulator)
