"""The topic table: every Zenoh key expression of the project is spelled here.

Keys live under a namespace (one per robot or profile, e.g. ``"sim"`` or
``"lab/robot1"``) so that several robots can share a network::

    ROBOT_STATE.key("sim")                  -> "sim/robot/state"
    liveliness_key("sim", "lp_controller")  -> "sim/alive/lp_controller"
    status_selector("sim")                  -> "sim/component/*/status"

A namespace is one or more ``/``-separated chunks; a component name is a single
chunk. Neither may be empty or contain the Zenoh wildcard and verbatim
characters ``* $ # ?``. Invalid names raise ``KeyExpressionError``.
"""

from __future__ import annotations

import fnmatch
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType
from typing import Generic, TypeVar

from pydantic import BaseModel

from messages.camera import CameraFrame
from messages.clock import Clock
from messages.commands import ArmCommand, BaseCommand
from messages.diagnostics import ControllerDiagnostics
from messages.goal import Goal
from messages.joints import JointStates
from messages.markers import MarkerDetections
from messages.obstacles import Obstacles
from messages.odometry import BaseOdometry
from messages.state import RobotState
from messages.status import ComponentStatus
from messages.stop import StopState
from messages.supervisor import SupervisorStatus
from messages.teleop import TeleopCommand
from messages.truth import SimTruth

M = TypeVar("M", bound=BaseModel)

_FORBIDDEN = frozenset("*$#?")


class KeyExpressionError(ValueError):
    """A namespace, component or parameter name that cannot form a key, or a key
    that is not of the expected shape."""


@dataclass(frozen=True)
class Topic(Generic[M]):
    """A topic: its ``name`` in this table (what profiles refer to), the
    ``suffix`` its key ends with, the message ``type`` it carries, and the largest payload
    (``max_bytes``) a subscriber takes: a larger one is refused before it is decoded.
    A ``ground_truth`` topic (the simulator's) is for tests and reports: no estimator or
    controller may read it."""

    name: str
    suffix: str
    type: type[M]
    max_bytes: int = 64 * 1024
    ground_truth: bool = False

    def key(self, namespace: str) -> str:
        """This topic's key under ``namespace``: ``"<namespace>/<suffix>"``."""
        return f"{check_namespace(namespace)}/{self.suffix}"


CAMERA_IMAGE = Topic("camera/image", "camera/image", CameraFrame, max_bytes=16 * 1024 * 1024)
"""Up to 16 MiB: a 1920 x 1080 bgr8 frame is 6.2 MB."""
VISION_MARKERS = Topic("vision/markers", "vision/markers", MarkerDetections)
BASE_ODOMETRY = Topic("base/odometry", "base/odometry", BaseOdometry)
ARM_JOINT_STATES = Topic("arm/joint_states", "arm/joint_states", JointStates)
ROBOT_STATE = Topic("robot/state", "robot/state", RobotState)
WORLD_OBSTACLES = Topic("world/obstacles", "world/obstacles", Obstacles)
WORLD_MARKERS = Topic("world/markers", "world/markers", MarkerDetections)
"""The markers of each camera frame placed in the world frame F0 by the state estimator."""
CONTROL_GOAL = Topic("control/goal", "control/goal", Goal)
GOAL_REQUEST = Topic("goal/request", "goal/request", Goal)
"""The operator's goal, for a supervisor that turns it into control/goal phase by phase."""
WORLD_GOAL = Topic("world/goal", "world/goal", Goal)
"""The goal the state estimator measures (eq. 6.3), where it is shown and not obeyed: in a
profile whose operator gives the goals on goal/request (deploy/sim_station.yaml)."""
SUPERVISOR_STATUS = Topic("supervisor/status", "supervisor/status", SupervisorStatus)
BASE_COMMAND = Topic("base/command", "base/command", BaseCommand)
ARM_COMMAND = Topic("arm/command", "arm/command", ArmCommand)
CONTROL_DIAGNOSTICS = Topic("control/diagnostics", "control/diagnostics", ControllerDiagnostics)
SIM_CLOCK = Topic("sim/clock", "sim/clock", Clock)
SIM_TRUTH = Topic("sim/truth", "sim/truth", SimTruth, ground_truth=True)
CONTROL_STOP = Topic("control/stop", "control/stop", StopState)
"""The latched emergency stop and its release (``components.stop_latch``)."""
TELEOP_COMMAND = Topic("teleop/command", "teleop/command", TeleopCommand)

TOPICS: Mapping[str, Topic] = MappingProxyType(
    {
        topic.name: topic
        for topic in (
            CAMERA_IMAGE,
            VISION_MARKERS,
            BASE_ODOMETRY,
            ARM_JOINT_STATES,
            ROBOT_STATE,
            WORLD_OBSTACLES,
            WORLD_MARKERS,
            CONTROL_GOAL,
            GOAL_REQUEST,
            WORLD_GOAL,
            SUPERVISOR_STATUS,
            BASE_COMMAND,
            ARM_COMMAND,
            CONTROL_DIAGNOSTICS,
            SIM_CLOCK,
            SIM_TRUTH,
            CONTROL_STOP,
            TELEOP_COMMAND,
        )
    }
)
"""Every topic, by name."""

FRAME_ANSWERS = (VISION_MARKERS, WORLD_MARKERS)
"""In lockstep, what answers a camera frame: the tracker's markers and the estimator's markers
placed in the world, stamped with the frame's stamp (the simulator waits for them; so does a
lockstep replay)."""

STATUS_TYPE = ComponentStatus
"""The message type published on ``status_key(namespace, component)``."""

MESSAGE_TYPES: tuple[type[BaseModel], ...] = tuple(
    dict.fromkeys((*(t.type for t in TOPICS.values()), STATUS_TYPE))
)
"""Every type that travels on its own on the wire (nested models excluded)."""

_BY_SUFFIX: Mapping[str, Topic] = MappingProxyType({t.suffix: t for t in TOPICS.values()})


def check_namespace(namespace: str) -> str:
    """Return ``namespace`` if it can prefix a key, else raise ``KeyExpressionError``."""
    return _check_path(namespace, "namespace")


def check_component(component: str) -> str:
    """Return ``component`` if it is a valid single-chunk component name."""
    if "/" in component:
        raise KeyExpressionError(f"component name {component!r} must not contain '/'")
    return _check_path(component, "component name")


def key(namespace: str, topic: Topic | str) -> str:
    """The key of ``topic`` (a ``Topic`` or a name in ``TOPICS``) under ``namespace``."""
    if isinstance(topic, str):
        if topic not in TOPICS:
            raise KeyExpressionError(f"unknown topic {topic!r}; known: {', '.join(TOPICS)}")
        topic = TOPICS[topic]
    return topic.key(namespace)


def topic_of_key(namespace: str, key_expr: str) -> Topic:
    """The topic whose key under ``namespace`` is ``key_expr`` (the inverse of ``key``)."""
    suffix = _strip_prefix(key_expr, f"{check_namespace(namespace)}/")
    if suffix not in _BY_SUFFIX:
        raise KeyExpressionError(f"{key_expr!r} is no topic of namespace {namespace!r}")
    return _BY_SUFFIX[suffix]


def namespace_selector(namespace: str) -> str:
    """Selects every key of the namespace: ``"<namespace>/**"``."""
    return f"{check_namespace(namespace)}/**"


def liveliness_key(namespace: str, component: str) -> str:
    """The liveliness token of a running component: ``"<ns>/alive/<component>"``."""
    return f"{check_namespace(namespace)}/alive/{check_component(component)}"


def liveliness_selector(namespace: str) -> str:
    """Selects every component's liveliness token: ``"<ns>/alive/*"``."""
    return f"{check_namespace(namespace)}/alive/*"


def component_of_liveliness_key(namespace: str, key_expr: str) -> str:
    """The component name in a liveliness key (the inverse of ``liveliness_key``)."""
    rest = _strip_prefix(key_expr, f"{check_namespace(namespace)}/alive/")
    return check_component(rest)


def status_key(namespace: str, component: str) -> str:
    """Where a component publishes its ``ComponentStatus``:
    ``"<ns>/component/<component>/status"``."""
    return f"{_component_prefix(namespace, component)}/status"


def status_selector(namespace: str) -> str:
    """Selects every component's status: ``"<ns>/component/*/status"``."""
    return f"{check_namespace(namespace)}/component/*/status"


def component_of_status_key(namespace: str, key_expr: str) -> str:
    """The component name in a status key (the inverse of ``status_key``)."""
    rest = _strip_prefix(key_expr, f"{check_namespace(namespace)}/component/")
    if not rest.endswith("/status"):
        raise KeyExpressionError(f"{key_expr!r} is no status key of namespace {namespace!r}")
    return check_component(rest.removesuffix("/status"))


def param_key(namespace: str, component: str, name: str) -> str:
    """A component's parameter: ``"<ns>/component/<component>/param/<name>"``.

    ``name`` may have several chunks (``"gains/eta"``).
    """
    return f"{_component_prefix(namespace, component)}/param/{_check_path(name, 'parameter')}"


def param_selector(namespace: str, component: str) -> str:
    """Selects every parameter of a component: ``"<ns>/component/<component>/param/**"``."""
    return f"{_component_prefix(namespace, component)}/param/**"


def all_params_selector(namespace: str) -> str:
    """Selects every parameter of every component: ``"<ns>/component/*/param/**"``."""
    return f"{check_namespace(namespace)}/component/*/param/**"


def param_of_key(namespace: str, key_expr: str) -> tuple[str, str]:
    """The component and the parameter name in a parameter key (the inverse of
    ``param_key``)."""
    rest = _strip_prefix(key_expr, f"{check_namespace(namespace)}/component/")
    component, marker, name = rest.partition("/param/")
    if not marker:
        raise KeyExpressionError(f"{key_expr!r} is no parameter key of namespace {namespace!r}")
    return check_component(component), _check_path(name, "parameter")


def _component_prefix(namespace: str, component: str) -> str:
    return f"{check_namespace(namespace)}/component/{check_component(component)}"


def _strip_prefix(key_expr: str, prefix: str) -> str:
    if not key_expr.startswith(prefix):
        raise KeyExpressionError(f"{key_expr!r} does not start with {prefix!r}")
    return key_expr.removeprefix(prefix)


def _check_path(path: str, what: str) -> str:
    if not path:
        raise KeyExpressionError(f"{what} must not be empty")
    if path.startswith("/") or path.endswith("/"):
        raise KeyExpressionError(f"{what} {path!r} must not start or end with '/'")
    if "//" in path:
        raise KeyExpressionError(f"{what} {path!r} must not contain an empty chunk '//'")
    forbidden = sorted(_FORBIDDEN.intersection(path))
    if forbidden:
        raise KeyExpressionError(
            f"{what} {path!r} must not contain the wildcard characters {' '.join(forbidden)}"
        )
    return path


def topics_matching(patterns: Sequence[str]) -> list[Topic]:
    """The topics whose names match one of the ``fnmatch`` patterns; ``ValueError`` when there
    is no pattern, or one matches no topic (a typo beside good patterns too)."""
    if not patterns:
        raise ValueError(
            f"keys: give at least one topic name pattern (the topics: {', '.join(TOPICS)})"
        )
    for pattern in patterns:
        if not fnmatch.filter(TOPICS, pattern):
            raise ValueError(
                f"keys: {pattern!r} matches no topic (the topics: {', '.join(TOPICS)})"
            )
    return [
        topic
        for topic in TOPICS.values()
        if any(fnmatch.fnmatch(topic.name, pattern) for pattern in patterns)
    ]
