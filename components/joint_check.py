"""A received message's joints against the robot's: a state or command whose joint names (and
so its size) are not the robot description's is refused, counted and logged, rate-limited,
with the names expected."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from components.runtime import Node


def mismatch(names: Sequence[str], expected: Sequence[str]) -> str:
    """Why joints ``names`` are not ``expected`` (empty when they are)."""
    if tuple(names) == tuple(expected):
        return ""
    return (
        f"{len(names)} joints ({', '.join(names)}); "
        f"the robot's are {len(expected)} ({', '.join(expected)})"
    )


def joints_match(
    node: Node, counter: str, what: str, names: Sequence[str], expected: Sequence[str]
) -> bool:
    """Whether ``what`` (a message's topic) names the robot's joints ``expected``; if not it is
    refused: counted in ``counter`` and said in one rate-limited line."""
    why = mismatch(names, expected)
    if why:
        node.count(counter)
        node.warn(counter, f"{what} refused: it has {why}")
    return not why
