"""Every running component's parameters as Foxglove's Parameters panel shows them, and a set from
the panel carried to the component as `parsimony param set` carries it.

A parameter is named ``<component>.<name>`` (``controller.eta``). The values come from one query
of every component's parameter queryables; a set is the component's own set
(``launch.query.set_param``): the component parses and checks the value against its
declaration (type, bounds, choices) and answers the value it now has, or why it refused it.
Before that, ``checked`` refuses what must not reach Zenoh or the component (a name no running
component has, or too long: a key of 64 KiB panics Zenoh; a value of no parameter's type, or
too long) and a set the view's user may not make (``zenoh.access.parameters``).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence

import zenoh
from foxglove import Parameter, ParameterType

from launch.query import DEFAULT_TIMEOUT_S, QueryError, set_param, value_text
from messages import topics
from messages.process import ParamValue, decode_value
from view.client_limits import (
    ECHO_CHARS,
    NAME_CHARS,
    PARAMETERS_AT_ONCE,
    VALUE_CHARS,
    cut,
    echo,
)

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
        return Parameter(full, value=[list(v) if isinstance(v, tuple | list) else v for v in items])
    return Parameter(full, value=value)


def split_name(full: str) -> tuple[str, str]:
    """``(component, name)`` of a Foxglove parameter's name, or ``QueryError``."""
    component, separator, name = full.partition(SEPARATOR)
    if not separator or not component or not name:
        raise QueryError(
            f"{echo(full)}: a parameter is named component{SEPARATOR}name "
            f"(controller{SEPARATOR}eta)"
        )
    return component, name


def _free(component: str) -> str:
    """Any component's parameters may be set (no reason to refuse)."""
    return ""


def running_parameters(
    session: zenoh.Session, namespace: str, timeout_s: float = DEFAULT_TIMEOUT_S
) -> list[Parameter]:
    """Every parameter of every running component, sorted by name (a reply that is no
    parameter's is skipped)."""
    found = []
    for reply in session.get(topics.all_params_selector(namespace), timeout=timeout_s):
        if reply.ok is None:
            continue
        try:
            component, name = topics.param_of_key(namespace, str(reply.ok.key_expr))
            found.append((component, name, decode_value(reply.ok.payload.to_bytes())))
        except ValueError:
            continue
    return [foxglove_parameter(*item) for item in sorted(found, key=lambda item: item[:2])]


class SetRefused(QueryError):
    """A parameter set that is not sent to the component; the text says why."""


def checked(
    parameter: Parameter, running: Iterable[str], may_set: Callable[[str], str] = _free
) -> tuple[str, str, str]:
    """``(component, name, value as text)`` of a set of one of the ``running`` parameters
    (their Foxglove names), or ``SetRefused``: a name too long or no running parameter's, a
    component ``may_set`` refuses (it says why, or empty), a value of no parameter's type or
    too long. Nothing of it reaches Zenoh before this."""
    full = parameter.name
    if len(full) > NAME_CHARS:
        raise SetRefused(f"a name of {len(full)} characters: at most {NAME_CHARS}")
    if full not in running:
        raise SetRefused(
            f"no running component has this parameter (they are named "
            f"component{SEPARATOR}name, as controller{SEPARATOR}eta)"
        )
    component, name = split_name(full)
    why = may_set(component)
    if why:
        raise SetRefused(why)
    value = parameter.get_value()
    if value is None:
        raise SetRefused("no value given")
    if isinstance(value, bytes):
        raise SetRefused("a byte array is no parameter's value")
    try:
        text = value_text(value)
    except (TypeError, ValueError, RecursionError):
        raise SetRefused("not a parameter's value") from None
    if len(text) > VALUE_CHARS:
        raise SetRefused(f"a value of {len(text)} characters: at most {VALUE_CHARS}")
    return component, name, text


def set_parameters(
    session: zenoh.Session,
    namespace: str,
    wanted: Sequence[Parameter],
    may_set: Callable[[str], str] = _free,
    timeout_s: float = DEFAULT_TIMEOUT_S,
) -> tuple[list[Parameter], list[str]]:
    """Set each parameter ``checked`` lets through on its component; the values they have
    afterwards (the new one, or the one kept after a refusal), and why each refused set was
    refused. Zenoh's own errors are raised."""
    if len(wanted) > PARAMETERS_AT_ONCE:
        return [], [f"a set of {len(wanted)} parameters: at most {PARAMETERS_AT_ONCE} at once"]
    running = {p.name: p for p in running_parameters(session, namespace, timeout_s)}
    values, refusals = [], []
    for parameter in wanted:
        try:
            component, name, text = checked(parameter, running, may_set)
            values.append(
                foxglove_parameter(
                    component, name, set_param(session, namespace, component, name, text, timeout_s)
                )
            )
        except QueryError as error:
            refusals.append(
                f"{cut(parameter.name, ECHO_CHARS)} = {echo(parameter.get_value())} "
                f"refused: {error}"
            )
            if parameter.name in running:
                values.append(running[parameter.name])
    return values, refusals
