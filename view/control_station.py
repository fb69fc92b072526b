"""What the clients of `parsimony view` may do beyond watching: send goals, set parameters.

The listener of the live view's server (``view.live_view``):

- Goals (``ClientPublish``): a client advertises a channel on goal/request (its key in the
  namespace, or its name) in JSON, a ``foxglove.PoseInFrame`` or ``foxglove.Pose`` (the 3-D
  panel's publish-pose tool); each message is checked (``view.client_goals``) and put on
  goal/request, stamped on the namespace's clock (``launch.tool_clock``). Only when the view's
  user may write goal/request (the profile's ``zenoh.access``): otherwise the capability is
  not advertised, and the server itself refuses any advertisement. A client sends at most
  ``client_limits.GOAL_RATE``; a goal over it is dropped, and the client told so.
- Parameters (``Parameters``): every running component's, as ``component.name``
  (``view.foxglove_params``); a set goes to the component, which checks it as it checks
  ``parsimony param set``, when the view's user may set that component's parameters
  (``zenoh.access.parameters``). Foxglove's protocol has no read-only parameters: a view whose
  user may set none still lists them, and refuses every set.
- The emergency stop, a boolean among the parameters (``view.station_stop``): true stops the
  namespace as ``parsimony stop`` does, false releases it as ``parsimony release`` does.
- Teleoperation (``view.station_teleop``): Foxglove's Teleop panel on a channel on
  teleop/command, when the view's user may command the robot.

What becomes of each goal and set is said in a status message naming the client it answers
(foxglove-sdk 0.30's Python server sends a status to every client, not to one), and logged.
A refusal is an error status that says why, at most ``client_limits.STATUS_CHARS`` long.

A Zenoh error on the station's session (closed, or a panic in Zenoh) is logged as an error and
counted (``session_errors``); the station opens a new session from the profile and goes on on
it (``failed`` says why it could not; ``view.station_session``).
"""

from __future__ import annotations

import functools
import logging
import threading
import time
from collections.abc import Callable
from typing import Any

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

from components.stop_latch import release_refusal, stop_text
from launch.tool_clock import ToolClock
from messages import codec, topics
from messages.header import Header
from messages.obstacles import circles_of
from profiles.access import tool_user
from profiles.profile import Profile
from view.client_goals import ENCODING, SCHEMAS, GoalRefused, client_goal
from view.client_limits import ECHO_CHARS, GOAL_RATE, STATUS_CHARS, Bucket, cut, echo
from view.foxglove_params import running_parameters, set_parameters
from view.station_session import SessionFailed, StationSession
from view.station_stop import STOP_PARAMETER, stop_given, stop_parameters
from view.station_teleop import TWIST_SCHEMAS, teleop_of, teleop_topic
from wbc import dq
from wbc.geometry.obstacles import Circle
from wbc.planar import offset_pose

SOURCE = "view"
"""The source named in the header of a goal the view passes on."""

log = logging.getLogger("parsimony.view")


def _answering(about: str, nothing: Any = None) -> Callable:
    """A listener callback that answers its client whatever happens: an error nobody foresaw
    is logged in one line, counted (``errors``) and said to the client, and ``nothing`` is
    returned (foxglove-sdk would log a traceback and answer nothing)."""

    def wrap(method: Callable) -> Callable:
        @functools.wraps(method)
        def answered(self: ControlStation, client: Client, *args: Any) -> Any:
            try:
                return method(self, client, *args)
            except Exception as error:
                with self._lock:
                    self.errors += 1
                log.error(
                    "view: %s failed: %s: %s",
                    method.__name__,
                    type(error).__name__,
                    cut(str(error), STATUS_CHARS),
                )
                self._status(
                    client,
                    about,
                    f"{about}: not done, the view failed: {type(error).__name__}: {error}",
                    StatusLevel.Error,
                )
                return nothing

        return answered

    return wrap


class ControlStation(ServerListener):
    """Goals and parameters from the view's clients into the namespace of ``profile``, on
    ``session`` (whose user is ``user``, a tool's by default). ``attach`` it to the server it
    listens to; ``close`` undeclares what it declared."""

    def __init__(self, session: zenoh.Session, profile: Profile, user: str | None = None) -> None:
        self.namespace, self._profile = profile.namespace, profile
        self.user = tool_user(user)
        access = profile.zenoh.access
        self.may_publish = access is None or access.may_write(topics.GOAL_REQUEST.name, self.user)
        self.may_set_any = access is None or any(
            access.may_set(spec.name, self.user) for spec in profile.components
        )
        scene = profile.scene
        self._offset = offset_pose(*scene.goal.offset) if scene is not None else dq.ONE.copy()
        self._server: WebSocketServer | None = None
        self._lock = threading.Lock()
        self._goal_channels: dict[tuple[int, int], ClientChannel] = {}
        self._teleop_channels: set[tuple[int, int]] = set()
        self._buckets: dict[int, Bucket] = {}
        self._q: np.ndarray | None = None
        self._obstacles: tuple[Circle, ...] = ()
        self.goals_sent = self.goals_refused = self.goals_dropped = self.errors = 0
        self._goal_out: zenoh.Publisher | None = None
        self._clock: ToolClock | None = None
        self._session = StationSession(session, profile, self.user, self._declare, self._lock)

    @property
    def session(self) -> zenoh.Session:
        """The station's Zenoh session (a new one after a failure)."""
        return self._session.session

    @property
    def session_errors(self) -> int:
        """How many times the station's session failed."""
        return self._session.errors

    @property
    def failed(self) -> str:
        """Why the station's session failed for good (a new one could not be opened)."""
        return self._session.failed

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
        self._session.close()

    def _declare(self, session: zenoh.Session) -> list:
        """What the station declares on ``session``: the goals' publisher, the namespace's
        clock and what a goal is checked against, when the user may send goals."""
        if not self.may_publish:
            return []
        self._goal_out = session.declare_publisher(topics.GOAL_REQUEST.key(self.namespace))
        self._clock = ToolClock(session, self._profile)
        return [self._goal_out, self._clock] + [
            session.declare_subscriber(topic.key(self.namespace), self._taker(topic))
            for topic in (topics.ROBOT_STATE, topics.WORLD_OBSTACLES)
        ]

    # -- goals ----------------------------------------------------------------------------

    def _taker(self, topic: topics.Topic) -> Callable[[zenoh.Sample], None]:
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

        return take

    @_answering("publish")
    def on_client_advertise(self, client: Client, channel: ClientChannel) -> None:
        key = (client.id, channel.id)
        if teleop_topic(channel.topic, self.namespace):
            refusal = release_refusal(self._profile, self.user, "teleoperate the robot")
            if channel.encoding != ENCODING or channel.schema_name not in TWIST_SCHEMAS:
                refusal = f"teleop/command takes {ENCODING} {' or '.join(TWIST_SCHEMAS)}"
            if refusal is not None:
                self._status(client, "teleop", refusal, StatusLevel.Error)
            else:
                with self._lock:
                    self._teleop_channels.add(key)
            return
        if channel.topic not in (topics.GOAL_REQUEST.name, topics.GOAL_REQUEST.key(self.namespace)):
            self._status(
                client,
                "publish",
                f"{echo(channel.topic)}: only {topics.GOAL_REQUEST.name} may be published",
                StatusLevel.Error,
            )
            return
        if channel.encoding != ENCODING or channel.schema_name not in SCHEMAS:
            self._status(
                client,
                "goal",
                f"goal/request in {echo(channel.encoding)} "
                f"{echo(channel.schema_name)} refused: it takes {ENCODING} "
                f"{' or '.join(SCHEMAS)}",
                StatusLevel.Error,
            )
            return
        with self._lock:
            self._goal_channels[key] = channel
            self._buckets.setdefault(client.id, Bucket(GOAL_RATE))

    @_answering("publish")
    def on_client_unadvertise(self, client: Client, client_channel_id: int) -> None:
        with self._lock:
            self._goal_channels.pop((client.id, client_channel_id), None)
            self._teleop_channels.discard((client.id, client_channel_id))
            if not any(id_ == client.id for id_, _ in self._goal_channels):
                self._buckets.pop(client.id, None)

    @_answering("goal")
    def on_message_data(self, client: Client, client_channel_id: int, data: bytes) -> None:
        if (client.id, client_channel_id) in self._teleop_channels:
            self._teleoperate(client, data)
            return
        now_s = time.monotonic()
        with self._lock:
            channel = self._goal_channels.get((client.id, client_channel_id))
            bucket = self._buckets.get(client.id)
            q, obstacles, clock = self._q, self._obstacles, self._clock
            if channel is None or bucket is None or clock is None:
                return  # refused when advertised, and said then
            within = bucket.take(now_s)
            told = 0 if within else bucket.tell(now_s)
            self.goals_dropped += 0 if within else 1
        if told:
            self._status(
                client,
                "goal",
                f"goal/request dropped: more than {GOAL_RATE} from "
                f"this client ({told} dropped); the next is taken in "
                f"{bucket.wait_s():.1f} s",
                StatusLevel.Warning,
            )
        if not within:
            return
        try:
            stamp_ns = clock.now_ns()
            if stamp_ns is None:
                raise GoalRefused("the simulator's clock has not reached the view yet")
            header = Header(stamp_ns=stamp_ns, frame="world", seq=self.goals_sent, source=SOURCE)
            goal = client_goal(channel.schema_name, data, self._offset, header, q, obstacles)
        except GoalRefused as error:
            with self._lock:
                self.goals_refused += 1
            self._status(client, "goal", f"goal/request refused: {error}", StatusLevel.Error)
            return
        try:
            self._session.run(lambda _: self._put(codec.encode(goal)))
        except SessionFailed as error:
            self._status(client, "goal", f"goal/request not sent: {error}", StatusLevel.Error)
            return
        with self._lock:
            self.goals_sent += 1
        x, y, z = dq.translation(np.array(goal.pose))[1:]
        self._status(
            client,
            "goal",
            f"goal/request sent: the gripper to ({x:.3f}, {y:.3f}, {z:.3f}) in world",
            StatusLevel.Info,
        )

    def _teleoperate(self, client: Client, data: bytes) -> None:
        """A twist of the Teleop panel onto teleop/command (what is wrong said, nothing sent)."""
        try:
            command = teleop_of(data, self.user)
            key = topics.TELEOP_COMMAND.key(self.namespace)
            self._session.run(lambda s: s.put(key, codec.encode(command)))
        except (ValueError, SessionFailed) as error:
            self._status(client, "teleop", f"teleop/command: {error}", StatusLevel.Error)

    def _put(self, payload: bytes) -> None:
        assert self._goal_out is not None
        self._goal_out.put(payload)

    # -- parameters -----------------------------------------------------------------------

    def _may_set(self, component: str) -> str:
        """Why the view's user may not set ``component``'s parameters, or empty."""
        access = self._profile.zenoh.access
        return "" if access is None else access.why_not_set(component, self.user)

    @_answering("parameters", [])
    def on_get_parameters(
        self, client: Client, param_names: list[str], request_id: str | None = None
    ) -> list[Parameter]:
        wanted = set(param_names)
        try:
            found = self._session.run(lambda s: running_parameters(s, self.namespace))
            found += self._session.run(lambda s: stop_parameters(s, self.namespace))
        except SessionFailed as error:
            self._status(client, "parameters", str(error), StatusLevel.Error)
            return []
        return [p for p in found if not wanted or p.name in wanted]

    def _give_stop(self, client: Client, value: Any) -> list[Parameter]:
        """Stop (``value`` true) or release (false) the namespace for ``client``."""
        given = stop_given(self._profile, self.user, client.id, value)
        if isinstance(given, str):
            self._status(client, "stop", given, StatusLevel.Error)
            return []
        key = topics.CONTROL_STOP.key(self.namespace)
        try:
            self._session.run(lambda s: s.put(key, codec.encode(given)))
        except SessionFailed as error:
            self._status(client, "stop", f"not sent: {error}", StatusLevel.Error)
            return []
        self._status(client, "stop", f"{STOP_PARAMETER}: {stop_text(given)}", StatusLevel.Info)
        return [Parameter(STOP_PARAMETER, value=given.stopped)]

    @_answering("parameters", [])
    def on_set_parameters(
        self, client: Client, parameters: list[Parameter], request_id: str | None = None
    ) -> list[Parameter]:
        stops = [p for p in parameters if p.name == STOP_PARAMETER]
        if stops:
            given = self._give_stop(client, stops[-1].get_value())
            rest = [p for p in parameters if p.name != STOP_PARAMETER]
            return given + (self.on_set_parameters(client, rest, request_id) if rest else [])
        if not self.may_set_any:
            self._status(
                client,
                "parameters",
                f"parameters are read-only in this view: "
                f"{self.user} may set no component's (zenoh.access.parameters)",
                StatusLevel.Error,
            )
            return self.on_get_parameters(client, [p.name for p in parameters], request_id)
        try:
            values, refusals = self._session.run(
                lambda s: set_parameters(s, self.namespace, parameters, self._may_set)
            )
        except SessionFailed as error:
            self._status(client, "parameters", str(error), StatusLevel.Error)
            return []
        for refusal in refusals:
            self._status(client, "parameters", refusal, StatusLevel.Error)
        if values and not refusals:
            self._status(
                client,
                "parameters",
                "set: "
                + ", ".join(f"{p.name} = {cut(repr(p.get_value()), ECHO_CHARS)}" for p in values),
                StatusLevel.Info,
            )
        return values

    def _status(self, client: Client, about: str, text: str, level: StatusLevel) -> None:
        """A status to the clients, naming the one it answers, cut to ``STATUS_CHARS``;
        logged too."""
        message = cut(f"client {client.id}: {text}", STATUS_CHARS - ECHO_CHARS)
        log.log(logging.WARNING if level == StatusLevel.Error else logging.INFO, "%s", message)
        if self._server is not None:
            self._server.publish_status(message, level, id=f"{about}/client{client.id}")
