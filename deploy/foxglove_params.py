"""Every running component's parameters as Foxglove's Parameters panel shows them, and a set from
the panel carried to the component as `parsimony param set` carries it.

A parameter is named ``<component>.<name>`` (``controller.eta``). The values come from one query
of every component's parameter queryables; a set is the component's own set
(``deploy.query.set_param``): the component parses and checks the value against its
declaration (type, bounds, choices) and answers the value it now has, or why it refused it.
"""

from __future__ import annotations

from collections.abc import Iterable

import zenoh
from foxglove import Parameter, ParameterType

from deploy.query import DEFAULT_TIMEOUT_S, QueryError, get_param, set_param, value_text
from messages import topics
from messages.process import ParamValue, decode_value

SEPARATOR = "."
"""Between a component's name and its parameter's in a Foxglove parameter's name."""


def foxglove_parameter(component: str, name: str, value: ParamValue) -> Parameter:
    """A value as Foxglove's parameter, floats marked as such (a whole 1.0 stays a float)."""
    full = f"{component}{SEPARATOR}{name}"
    if isinstance(value, float):
        return Parameter(full, value=value, type=ParameterType.Float64)
    if isinstance(value, tuple | list):
        items = list(value)
        if all(isinstance(v, float) for v in items):
            return Parameter(full, value=items, type=ParameterType.Float64Array)
        return Parameter(full, value=[list(v) if isinstance(v, tuple | list) else v
                                      for v in items])  # fmt: skip
    return Parameter(full, value=value)


def split_name(full: str) -> tuple[str, str]:
    """``(component, name)`` of a Foxglove parameter's name, or ``QueryError``."""
    component, separator, name = full.partition(SEPARATOR)
    if not separator or not component or not name:
        raise QueryError(f"{full!r}: a parameter is named component{SEPARATOR}name "
                         f"(controller{SEPARATOR}eta)")  # fmt: skip
    return component, name


def running_parameters(
    session: zenoh.Session, namespace: str, timeout_s: float = DEFAULT_TIMEOUT_S
) -> list[Parameter]:
    """Every parameter of every running component, sorted by name."""
    found = []
    for reply in session.get(topics.all_params_selector(namespace), timeout=timeout_s):
        if reply.ok is None:
            continue
        component, name = topics.param_of_key(namespace, str(reply.ok.key_expr))
        found.append((component, name, decode_value(reply.ok.payload.to_bytes())))
    return [foxglove_parameter(*item) for item in sorted(found, key=lambda item: item[:2])]


def set_parameters(
    session: zenoh.Session, namespace: str, wanted: Iterable[Parameter],
    timeout_s: float = DEFAULT_TIMEOUT_S,
) -> tuple[list[Parameter], list[str]]:  # fmt: skip
    """Set each parameter on its component; the values they have afterwards (the new one, or
    the one kept after a refusal), and why each refused set was refused."""
    values, refusals = [], []
    for parameter in wanted:
        try:
            component, name = split_name(parameter.name)
        except QueryError as error:
            refusals.append(str(error))
            continue
        value = parameter.get_value()
        try:
            if value is None:
                raise QueryError("no value given")
            now = set_param(session, namespace, component, name, value_text(value), timeout_s)
        except QueryError as error:
            refusals.append(f"{parameter.name} = {value!r} refused: {error}")
            try:
                now = get_param(session, namespace, component, name, timeout_s)
            except QueryError:
                continue
        values.append(foxglove_parameter(component, name, now))
    return values, refusals
