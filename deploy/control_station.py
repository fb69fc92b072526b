"""What the clients of `parsimony view` may do beyond watching: send goals, set parameters.

The listener of the live view's server (``record.live_view``):

- Goals (``ClientPublish``): a client advertises a channel on goal/request (its key in the
  namespace, or its name) in JSON, a ``foxglove.PoseInFrame`` or ``foxglove.Pose`` (the 3-D
  panel's publish-pose tool); each message is checked (``deploy.client_goals``) and put on
  goal/request, stamped on the namespace's clock. Only when the view's user may write
  goal/request (the profile's ``zenoh.access``): otherwise the capability is not advertised,
  and the server itself refuses any advertisement.
- Parameters (``Parameters``): every running component's, as ``component.name``
  (``deploy.foxglove_params``); a set goes to the component, which checks it as it checks
  ``parsimony param set``.

What becomes of each goal and set is said in a status message naming the client it answers
(foxglove-sdk 0.30's Python server sends a status to every client, not to one), and logged.
A refusal is an error status that says why.
"""

from __future__ import annotations

import logging
import threading
import time

import numpy as np
import zenoh
from foxglove import Parameter, StatusLevel
from foxglove.websocket import (
    Capability,
    Client,
    ClientChannel,
    ServerListener,
    WebSocketServer,
)

from deploy.client_goals import ENCODING, SCHEMAS, GoalRefused, client_goal
from deploy.foxglove_params import running_parameters, set_parameters
from messages import codec, topics
from messages.header import Header
from messages.obstacles import circles_of
from profiles.access import tool_user
from profiles.profile import Profile
from wbc import dq
from wbc.obstacles import Circle
from wbc.planar import offset_pose

SOURCE = "view"
"""The source named in the header of a goal the view passes on."""

log = logging.getLogger("parsimony.view")


class ControlStation(ServerListener):
    """Goals and parameters from the view's clients into the namespace of ``profile``, on
    ``session`` (whose user is ``user``, a tool's by default). ``attach`` it to the server it
    listens to; ``close`` undeclares what it declared."""

    def __init__(self, session: zenoh.Session, profile: Profile, user: str | None = None) -> None:
        self.session, self.namespace = session, profile.namespace
        self.user = tool_user(user)
        access = profile.zenoh.access
        self.may_publish = access is None or access.may_write(topics.GOAL_REQUEST.name, self.user)
        scene = profile.scene
        self._offset = offset_pose(*scene.goal.offset) if scene is not None else dq.ONE.copy()
        self._on_sim_clock = profile.clock == "sim"
        self._server: WebSocketServer | None = None
        self._lock = threading.Lock()
        self._goal_channels: dict[tuple[int, int], ClientChannel] = {}
        self._q: np.ndarray | None = None
        self._obstacles: tuple[Circle, ...] = ()
        self._clock_ns: int | None = None
        self.goals_sent = 0
        self._declared: list = []
        self._goal_out = None
        if self.may_publish:
            self._goal_out = session.declare_publisher(topics.GOAL_REQUEST.key(self.namespace))
            self._declared = [self._goal_out] + [
                session.declare_subscriber(topic.key(self.namespace), self._taker(topic))
                for topic in (topics.ROBOT_STATE, topics.WORLD_OBSTACLES, topics.SIM_CLOCK)
            ]

    @property
    def capabilities(self) -> list[Capability]:
        """What the server advertises: parameters always, publishing if the user may."""
        return [Capability.Parameters, *([Capability.ClientPublish] if self.may_publish else [])]

    @property
    def encodings(self) -> list[str]:
        return [ENCODING] if self.may_publish else []

    def attach(self, server: WebSocketServer) -> None:
        self._server = server

    def close(self) -> None:
        for declared in self._declared:
            declared.undeclare()
        self._declared = []

    # -- goals ----------------------------------------------------------------------------

    def _taker(self, topic: topics.Topic):
        def take(sample: zenoh.Sample) -> None:
            try:
                message = codec.decode(sample.payload.to_bytes(), topic.type)
            except codec.DecodeError:
                return  # the view's own subscriber counts and says it
            with self._lock:
                if topic is topics.ROBOT_STATE and message.valid:
                    self._q = np.array(message.configuration())
                elif topic is topics.WORLD_OBSTACLES:
                    self._obstacles = circles_of(message)
                elif topic is topics.SIM_CLOCK:
                    self._clock_ns = message.stamp_ns

        return take

    def on_client_advertise(self, client: Client, channel: ClientChannel) -> None:
        key = (client.id, channel.id)
        if channel.topic not in (topics.GOAL_REQUEST.name, topics.GOAL_REQUEST.key(self.namespace)):
            self._status(client, "publish", f"{channel.topic}: only {topics.GOAL_REQUEST.name} "
                         "may be published", StatusLevel.Error)  # fmt: skip
            return
        if channel.encoding != ENCODING or channel.schema_name not in SCHEMAS:
            self._status(client, "goal", f"goal/request in {channel.encoding} "
                         f"{channel.schema_name!r} refused: it takes {ENCODING} "
                         f"{' or '.join(SCHEMAS)}", StatusLevel.Error)  # fmt: skip
            return
        with self._lock:
            self._goal_channels[key] = channel

    def on_client_unadvertise(self, client: Client, client_channel_id: int) -> None:
        with self._lock:
            self._goal_channels.pop((client.id, client_channel_id), None)

    def on_message_data(self, client: Client, client_channel_id: int, data: bytes) -> None:
        with self._lock:
            channel = self._goal_channels.get((client.id, client_channel_id))
            q, obstacles, clock_ns = self._q, self._obstacles, self._clock_ns
        if channel is None or self._goal_out is None:
            return  # refused when advertised, and said then
        try:
            stamp_ns = clock_ns if self._on_sim_clock else time.time_ns()
            if stamp_ns is None:
                raise GoalRefused("the simulator's clock has not reached the view yet")
            header = Header(stamp_ns=stamp_ns, frame="world", seq=self.goals_sent,
                            source=SOURCE)  # fmt: skip
            goal = client_goal(channel.schema_name, data, self._offset, header, q, obstacles)
        except GoalRefused as error:
            self._status(client, "goal", f"goal/request refused: {error}", StatusLevel.Error)
            return
        self._goal_out.put(codec.encode(goal))
        self.goals_sent += 1
        x, y, z = dq.translation(np.array(goal.pose))[1:]
        self._status(client, "goal", f"goal/request sent: the gripper to ({x:.3f}, {y:.3f}, "
                     f"{z:.3f}) in world", StatusLevel.Info)  # fmt: skip

    # -- parameters -----------------------------------------------------------------------

    def on_get_parameters(self, client: Client, param_names: list[str],
                          request_id: str | None = None) -> list[Parameter]:  # fmt: skip
        found = running_parameters(self.session, self.namespace)
        return [p for p in found if not param_names or p.name in param_names]

    def on_set_parameters(self, client: Client, parameters: list[Parameter],
                          request_id: str | None = None) -> list[Parameter]:  # fmt: skip
        values, refusals = set_parameters(self.session, self.namespace, parameters)
        for refusal in refusals:
            self._status(client, "parameters", refusal, StatusLevel.Error)
        if values and not refusals:
            self._status(client, "parameters", "set: " + ", ".join(
                f"{p.name} = {p.get_value()!r}" for p in values), StatusLevel.Info)  # fmt: skip
        return values

    def _status(self, client: Client, about: str, text: str, level: StatusLevel) -> None:
        """A status to the clients, naming the one it answers; logged too."""
        message = f"client {client.id}: {text}"
        log.log(logging.WARNING if level == StatusLevel.Error else logging.INFO, "%s", message)
        if self._server is not None:
            self._server.publish_status(message, level, id=f"{about}/client{client.id}")
