"""What a tool asks a running system: who is alive, their status, their parameters, who
writes a topic.

Used by ``parsimony status``, ``param``, ``topic`` and ``goal``. A ``Target`` says which
namespace to look at and how to reach its router; each question is a Zenoh
query with a timeout on a client session.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import zenoh

from launch.graph import dataflow
from launch.zenoh_error import zenoh_error_text
from messages import codec, topics
from messages.process import ParamValue, decode_value
from messages.status import ComponentStatus
from profiles.network import ZenohSettings
from profiles.profile import Profile, load_profile

DEFAULT_ROUTER = "tcp/127.0.0.1:7447"
"""Where tools look for the router when given a namespace and no endpoint."""

DEFAULT_TIMEOUT_S = 2.0
"""How long a tool waits for replies."""


class QueryError(Exception):
    """A question the running system did not or could not answer."""


class NoRouter(QueryError):
    """The router of a target cannot be reached: there is no running system to ask."""


@dataclass(frozen=True)
class Target:
    """A namespace and how to reach the router that serves it."""

    namespace: str
    zenoh: ZenohSettings

    @classmethod
    def from_profile(cls, path: str | Path) -> Target:
        """The namespace and router of a profile (raises ``ProfileError``)."""
        profile = load_profile(path)
        return cls(profile.namespace, profile.zenoh)

    @classmethod
    def from_namespace(cls, namespace: str, router: str = DEFAULT_ROUTER) -> Target:
        """A namespace served by the router at ``router`` (a loopback endpoint)."""
        topics.check_namespace(namespace)
        return cls(namespace, ZenohSettings(router=[router]))

    def open(self) -> zenoh.Session:
        """A client session to the router; ``QueryError`` if it cannot connect."""
        try:
            return zenoh.open(self.zenoh.client_config())
        except zenoh.ZError as error:
            where = ", ".join(self.zenoh.connect_endpoints)
            reason = zenoh_error_text(error)
            raise NoRouter(f"cannot reach a router at {where}: {reason}") from error


def live_components(
    session: zenoh.Session, namespace: str, timeout_s: float = DEFAULT_TIMEOUT_S
) -> list[str]:
    """The names of the components whose liveliness token is present, sorted."""
    names = {
        topics.component_of_liveliness_key(namespace, str(reply.ok.key_expr))
        for reply in session.liveliness().get(
            topics.liveliness_selector(namespace), timeout=timeout_s
        )
        if reply.ok is not None
    }
    return sorted(names)


def live_writers(
    session: zenoh.Session, profile: Profile, topic: str, timeout_s: float = DEFAULT_TIMEOUT_S
) -> list[str]:
    """The components of ``profile`` that declare they write ``topic`` (``launch.graph``, its
    remaps too) and whose liveliness token is present: what a tool publishes there, they
    overwrite with their next message."""
    writers = dataflow(profile).writers(topic)
    if not writers:
        return []
    alive = set(live_components(session, profile.namespace, timeout_s))
    return [name for name in writers if name in alive]


def overwritten_by(writers: list[str], key: str) -> str:
    """What a message a tool publishes on ``key`` meets when ``writers`` (running components,
    ``live_writers``) write it too, in words: their next message replaces it."""
    one = len(writers) == 1
    return (
        f"{', '.join(writers)} {'writes' if one else 'write'} {key} in this profile and "
        f"{'is' if one else 'are'} running: {'its' if one else 'their'} next message "
        "replaces what is published here"
    )


def statuses(
    session: zenoh.Session, namespace: str, timeout_s: float = DEFAULT_TIMEOUT_S
) -> dict[str, ComponentStatus]:
    """The status every component of the namespace answers, by name."""
    found = {}
    for reply in session.get(topics.status_selector(namespace), timeout=timeout_s):
        if reply.ok is not None:
            key = str(reply.ok.key_expr)
            status = codec.decode(reply.ok.payload.to_bytes(), topics.STATUS_TYPE, key)
            found[status.name] = status
    return found


def get_param(
    session: zenoh.Session,
    namespace: str,
    component: str,
    name: str,
    timeout_s: float = DEFAULT_TIMEOUT_S,
) -> ParamValue:
    """The current value of a component's parameter."""
    return _param_query(session, namespace, component, name, None, timeout_s)


def value_text(value: object) -> str:
    """A value as ``set_param`` takes it, as typed on a command line: true, 0.5, pose,
    [0.6, 0.0, 0.0]."""
    return value if isinstance(value, str) else json.dumps(value)


def set_param(
    session: zenoh.Session,
    namespace: str,
    component: str,
    name: str,
    text: str,
    timeout_s: float = DEFAULT_TIMEOUT_S,
) -> ParamValue:
    """Set a component's parameter from its text form; return the value it now has."""
    return _param_query(session, namespace, component, name, text, timeout_s)


def all_params(
    session: zenoh.Session, namespace: str, component: str, timeout_s: float = DEFAULT_TIMEOUT_S
) -> dict[str, ParamValue]:
    """Every parameter of a running component and its value, by name."""
    prefix = topics.param_key(namespace, component, "x")[:-1]
    values = {}
    for reply in session.get(topics.param_selector(namespace, component), timeout=timeout_s):
        if reply.ok is not None:
            name = str(reply.ok.key_expr).removeprefix(prefix)
            values[name] = decode_value(reply.ok.payload.to_bytes())
    if not values:
        raise QueryError(
            f"no reply from {component!r} in namespace {namespace!r} within "
            f"{timeout_s} s (is it running?)"
        )
    return dict(sorted(values.items()))


def status_of(
    session: zenoh.Session, namespace: str, component: str, timeout_s: float = DEFAULT_TIMEOUT_S
) -> ComponentStatus:
    """One running component's status."""
    key = topics.status_key(namespace, component)
    for reply in session.get(key, timeout=timeout_s):
        if reply.ok is not None:
            return codec.decode(reply.ok.payload.to_bytes(), topics.STATUS_TYPE, key)
    raise QueryError(
        f"no status from {component!r} in namespace {namespace!r} within "
        f"{timeout_s} s (is it running?)"
    )


def _param_query(
    session: zenoh.Session,
    namespace: str,
    component: str,
    name: str,
    text: str | None,
    timeout_s: float,
) -> ParamValue:
    key = topics.param_key(namespace, component, name)
    for reply in session.get(key, payload=text, timeout=timeout_s):
        if reply.ok is not None:
            return decode_value(reply.ok.payload.to_bytes())
        raise QueryError(reply.err.payload.to_string())
    raise QueryError(
        f"no reply from {component!r} in namespace {namespace!r} within {timeout_s} s "
        "(is it running?)"
    )
