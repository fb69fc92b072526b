"""Who may connect and who may publish what: Zenoh user/password authentication and ACL.

A profile that says ``zenoh.access`` names a credentials file (``user:password`` per line,
the router's dictionary), per topic the users who may write it, and per component the users
who may set its parameters (``"*"``: every component not named)::

    zenoh:
      mode: client
      access:
        credentials: credentials.txt
        writers:
          control/goal: [operator]
        parameters:
          "*": [operator]

A session without a user and password of the file is refused by the router. Every component
authenticates as its own name; tools as ``$PARSIMONY_USER`` (default ``operator``). A put on a
listed topic from any other user is dropped by the router's access control. The rules act in
the router, so the profile must run in ``client`` mode (peers would link directly, past them).
A parameter is read and set by one query, which the router cannot tell apart: the tools that
set parameters (``parsimony param set|load``, the live view's clients) obey ``parameters``
themselves.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, model_validator

from messages import topics

USER_ENV = "PARSIMONY_USER"
"""The user a tool (``parsimony status``, ``topic``, ``param`` ...) authenticates as."""
DEFAULT_TOOL_USER = "operator"
EVERY_COMPONENT = "*"
"""In ``parameters``: every component the profile's rules do not name."""


def tool_user(user: str | None = None) -> str:
    """``user``, or the user a tool authenticates as: ``$PARSIMONY_USER``, else ``operator``."""
    return user or os.environ.get(USER_ENV, DEFAULT_TOOL_USER)


def read_credentials(path: Path) -> dict[str, str]:
    """``user -> password`` from a file of ``user:password`` lines (blank lines and # skipped)."""
    users = {}
    for number, line in enumerate(path.read_text().splitlines(), start=1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        user, colon, password = line.partition(":")
        if not colon or not user or not password:
            raise ValueError(f"{path}:{number}: expected user:password")
        users[user] = password
    return users


class AccessSettings(BaseModel):
    """The credentials file, per topic of the table the users who may write it, and per
    component (``EVERY_COMPONENT``: those not named) the users who may set its parameters;
    a topic or component not named is free to every user."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    credentials: Path
    writers: dict[str, list[str]] = {}
    parameters: dict[str, list[str]] = {}

    @model_validator(mode="after")
    def _known_topics_and_users(self) -> AccessSettings:
        try:
            users = read_credentials(self.credentials)
        except OSError as error:
            raise ValueError(
                f"credentials: cannot read {self.credentials}: {error.strerror}"
            ) from error
        for topic, writers in self.writers.items():
            if topic not in topics.TOPICS:
                raise ValueError(
                    f"writers.{topic}: not a topic of the table ({', '.join(topics.TOPICS)})"
                )
            unknown = sorted(set(writers) - set(users))
            if unknown:
                raise ValueError(f"writers.{topic}: {unknown} not in {self.credentials}")
        for component, setters in self.parameters.items():
            unknown = sorted(set(setters) - set(users))
            if unknown:
                raise ValueError(f"parameters.{component}: {unknown} not in {self.credentials}")
        return self

    def users(self) -> dict[str, str]:
        return read_credentials(self.credentials)

    def router_json(self, namespace: str) -> dict[str, Any]:
        """The router's authentication and access control: every user outside a topic's
        writers is denied puts on its key."""
        users = set(self.users())
        rules, subjects, policies = [], [], []
        for index, (topic, writers) in enumerate(sorted(self.writers.items())):
            others = sorted(users - set(writers))
            if not others:
                continue
            rules.append(
                {
                    "id": f"no-put-{index}",
                    "permission": "deny",
                    "flows": ["ingress"],
                    "messages": ["put", "delete"],
                    "key_exprs": [topics.TOPICS[topic].key(namespace)],
                }
            )
            subjects.append({"id": f"not-writers-{index}", "usernames": others})
            policies.append({"rules": [f"no-put-{index}"], "subjects": [f"not-writers-{index}"]})
        return {
            "transport/auth/usrpwd": {"dictionary_file": str(self.credentials)},
            "access_control": {
                "enabled": True,
                "default_permission": "allow",
                "rules": rules,
                "subjects": subjects,
                "policies": policies,
            },
        }

    def may_write(self, topic: str, user: str | None) -> bool:
        """Whether ``user`` (a tool's: ``$PARSIMONY_USER``) may put on ``topic``: the topic
        names no writers, or names the user."""
        return topic not in self.writers or tool_user(user) in self.writers[topic]

    def may_set(self, component: str, user: str | None) -> bool:
        """Whether ``user`` (a tool's: ``$PARSIMONY_USER``) may set ``component``'s parameters:
        ``parameters`` names neither the component nor ``EVERY_COMPONENT``, or names the user
        where it names the component (else under ``EVERY_COMPONENT``)."""
        setters = self.parameters.get(component, self.parameters.get(EVERY_COMPONENT))
        return setters is None or tool_user(user) in setters

    def why_not_set(self, component: str, user: str | None) -> str:
        """Why ``user`` (a tool's: ``$PARSIMONY_USER``) may not set ``component``'s parameters,
        said alike by every tool that sets them; empty where it may."""
        if self.may_set(component, user):
            return ""
        return f"{tool_user(user)} may not set {component}'s parameters (zenoh.access.parameters)"

    def session_json(self, user: str | None) -> dict[str, Any]:
        """A session's credentials: ``user`` (a tool's: ``$PARSIMONY_USER``) and its password."""
        user = tool_user(user)
        users = self.users()
        if user not in users:
            raise ValueError(f"user {user!r} has no line in {self.credentials}")
        return {"transport/auth/usrpwd": {"user": user, "password": users[user]}}


def insert(config: Any, entries: dict[str, Any]) -> None:
    """Insert each ``path: value`` into a ``zenoh.Config``."""
    for path, value in entries.items():
        config.insert_json5(path, json.dumps(value))
