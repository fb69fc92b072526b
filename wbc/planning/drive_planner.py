"""The base's way round circular obstacles: the shortest path among discs, on their visibility
graph.

Each obstacle circle (c_i, r_i) is grown into a disc of radius R_i = r_i + clearance + slack:
``clearance`` the base's body radius and the LP's margin, which the way must keep, and
``slack`` the room the LP's obstacle constraint wants for its point ahead of the axle, given
up where the start or the target stands closer (R_i shrinks to its distance from c_i, never
below r_i + clearance for the target). A shortest path for a point among discs is made of
straight segments tangent to the discs and arcs on their boundaries, so it lies on the graph
whose nodes are the start s, the target g and the tangent points, and whose edges are

    the segments s-g, s-T and T-g to the tangent points T of every disc (2 each, at the
    angles atan2(p - c_i) +- acos(R_i / ||p - c_i||)), the outer bitangents of every two discs
    (angles theta +- acos((R_i - R_j) / D)) and the inner ones (theta +- acos((R_i + R_j) / D),
    and + pi on disc j), each kept when no disc's interior meets it;
    the arcs between neighbouring tangent points of a disc, R_i |delta angle| long, kept when
    no other disc covers them;

and Dijkstra's search on it gives the shortest way exactly (no sampling, no randomness).
``WayPlanner`` searches the graph of s and the discs once, then joins each target to it by
its own tangents (the staging planner asks for many targets from one start). A target inside
a grown disc, or walled off, has no way, and the reason says which. The way is handed to the
drive as waypoints: each arc becomes the corners of the polygon circumscribed about it
(corners at R_i / cos(delta / 2), at most ``max_turn`` apart), so every leg between waypoints
is tangent to, and outside of, the grown discs (``wbc.planning.way``).

The graph of n discs has O(n^2) nodes and its edges take O(n^3) work (256 discs: 70,000
nodes, seconds of CPU), so a planner given a ``deadline`` on its thread's CPU clock raises
``OutOfBudget`` as soon as it finds it passed, wherever it is in the work.
"""

from __future__ import annotations

import heapq
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from wbc.geometry.obstacles import Circle
from wbc.planning.disc_geometry import (
    TAU,
    TOUCH,
    bitangents,
    clear,
    covered,
    overlaps,
    segment_clear,
)
from wbc.planning.way import Arc, Way
from wbc.validation import require_finite

Array = np.ndarray

ROOM = 1e-4
"""How far inside a start's or target's distance from a centre its disc shrinks to, m."""

SEARCH_CHECK = 1024
"""Dijkstra's search looks at the CPU clock once per this many nodes it settles."""


class OutOfBudget(Exception):
    """A ``WayPlanner``'s CPU deadline passed before its work was done."""


def plan_way(
    start: Array,
    target: Array,
    obstacles: Sequence[Circle],
    clearance: float,
    slack: float = 0.0,
    max_turn: float = math.pi / 4,
) -> Way:
    """The shortest way from ``start`` (x, y) to ``target`` (x, y) for a point that keeps
    ``clearance`` (and ``slack`` where it can) from every obstacle: the module's docstring."""
    return WayPlanner(start, obstacles, clearance, slack, max_turn).to(target)


@dataclass(frozen=True)
class _Node:
    point: Array
    disc: int
    """The disc the node lies on, -1 for the start and the target."""
    angle: float


Edges = dict[int, list[tuple[int, float, float | None]]]
"""For each node: (neighbour, length, sweep): the arc's signed sweep from the node to its
neighbour (rad, counter-clockwise > 0), None for a segment."""


class WayPlanner:
    """Shortest ways from one start round ``obstacles``: the graph of the start and the discs
    is searched once (Dijkstra from the start), and ``to`` joins each target to it. Past
    ``deadline`` (a ``time.thread_time()``, s) building the graph or a way raises
    ``OutOfBudget``."""

    def __init__(
        self,
        start: Array,
        obstacles: Sequence[Circle],
        clearance: float,
        slack: float = 0.0,
        max_turn: float = math.pi / 4,
        target: Array | None = None,
        deadline: float = math.inf,
    ) -> None:
        self.deadline = deadline
        self.origin = require_finite("start", start)[:2]
        self.obstacles = tuple(obstacles)
        self.clearance, self.slack, self.max_turn = clearance, slack, max_turn
        self.reason = ""
        for index, c in enumerate(self.obstacles, start=1):
            require_finite(f"obstacle {index}", (c.x, c.y, c.radius))
            if math.hypot(self.origin[0] - c.x, self.origin[1] - c.y) < c.radius:
                self.reason = f"the base stands inside obstacle {index} at ({c.x:.2f}, {c.y:.2f})"
        self.start = self.origin if self.reason else self._escape()
        """Where the way round the discs begins: the origin, or the point straight out of the
        slack of the disc it stands in."""
        near = [self.start] if target is None else [self.start, target]
        self.centres = np.array([(c.x, c.y) for c in self.obstacles], dtype=float).reshape(-1, 2)
        self.radii = np.array(
            [
                max(
                    c.radius,
                    min(
                        [c.radius + clearance + slack]
                        + [float(np.hypot(*(p - centre))) - ROOM for p in near]
                    ),
                )
                for c, centre in zip(self.obstacles, self.centres, strict=True)
            ]
        )
        self.shrunk_for_target = target is not None
        self._covers: list[list[tuple[float, float]]] = []
        """For each disc, the arcs of its circle that the other discs cover (``covered``)."""
        for disc in range(len(self.obstacles)):
            self._check_budget()
            arcs = (
                covered(*self._disc(disc), *self._disc(other))
                for other in range(len(self.obstacles))
                if other != disc
            )
            self._covers.append([arc for arc in arcs if arc is not None])
        self.nodes = [_Node(self.start, -1, 0.0)]
        self.edges: Edges = {0: []}
        self._of_disc: dict[int, list[int]] = {}
        """The nodes on each disc."""
        discs = range(0 if self.reason else len(self.obstacles))
        for disc in discs:
            self._check_budget()
            self._tangents(0, disc)
            for other in range(disc + 1, len(self.obstacles)):
                for a, b in bitangents(self._disc(disc), self._disc(other)):
                    self._link(self._node(disc, a), self._node(other, b))
        self._on = [self._link_arcs(disc) for disc in discs]
        self.distance, self.previous = self._search()

    def to(self, target: Array) -> Way:
        """The shortest way from the start to ``target`` (x, y), or why there is none."""
        target = require_finite("target", target)[:2]
        if self.reason:
            return self._none(target, self.reason)
        gaps = np.hypot(*(target - self.centres).T) if len(self.radii) else np.zeros(0)
        for index, c in enumerate(self.obstacles, start=1):
            if gaps[index - 1] < c.radius + self.clearance - TOUCH:
                return self._none(
                    target,
                    f"the target ({target[0]:.2f}, {target[1]:.2f}) lies "
                    f"within {self.clearance:g} m of obstacle {index} at "
                    f"({c.x:.2f}, {c.y:.2f})",
                )
        if np.any(gaps < self.radii) and not self.shrunk_for_target:
            return WayPlanner(
                self.origin,
                self.obstacles,
                self.clearance,
                self.slack,
                self.max_turn,
                target,
                self.deadline,
            ).to(target)
        best: tuple[float, list[tuple[int, float | None]]] = (math.inf, [])
        if clear(self.start, target, self.centres, self.radii):
            best = (float(np.hypot(*(target - self.start))), [(0, None)])
        for disc in range(len(self.obstacles)):
            self._check_budget()
            for angle in self._tangent_angles(target, disc):
                point = self._point(disc, angle)
                if self._inside_another(point, disc) or not clear(
                    point, target, self.centres, self.radii
                ):
                    continue
                for node, sweep in self._arcs_into(disc, angle):
                    length = (
                        self.distance[node]
                        + self.radii[disc] * abs(sweep)
                        + float(np.hypot(*(target - point)))
                    )
                    if length < best[0]:
                        best = (length, self._path(node) + [(-1, sweep)])
        if not math.isfinite(best[0]):
            return self._none(
                target,
                f"no way round the obstacles from ({self.start[0]:.2f}, "
                f"{self.start[1]:.2f}) to ({target[0]:.2f}, {target[1]:.2f})",
            )
        return self._way(target, *best)

    def _check_budget(self) -> None:
        if time.thread_time() > self.deadline:
            raise OutOfBudget(f"the way round {len(self.obstacles)} obstacles took it all")

    def _none(self, target: Array, reason: str) -> Way:
        return Way(self.origin, target, (), math.inf, reason, ())

    def _escape(self) -> Array:
        """The point straight out of the grown disc (r + clearance + slack) the origin stands
        in, just outside it, where the segment there keeps the clearance from the others and
        the point stands in no other; else the origin. Inside that disc the LP's obstacle
        constraint 5.28 may leave no solution for a leg that passes the obstacle, while one
        that moves straight away from it does not engage the constraint at all."""
        full = [c.radius + self.clearance + self.slack for c in self.obstacles]
        inside = [
            (float(np.hypot(self.origin[0] - c.x, self.origin[1] - c.y)), index)
            for index, c in enumerate(self.obstacles)
        ]
        inside = [(d, i) for d, i in inside if d < full[i]]
        if not inside:
            return self.origin
        distance, index = min(inside)
        c = self.obstacles[index]
        out = np.array([c.x, c.y]) + (self.origin - [c.x, c.y]) / distance * (full[index] + ROOM)
        others = [o for i, o in enumerate(self.obstacles) if i != index]
        if segment_clear(self.origin, out, others, self.clearance) and all(
            np.hypot(out[0] - o.x, out[1] - o.y) >= full[i]
            for i, o in enumerate(self.obstacles)
            if i != index
        ):
            return out
        return self.origin

    def _disc(self, disc: int) -> tuple[Array, float]:
        return self.centres[disc], float(self.radii[disc])

    def _point(self, disc: int, angle: float) -> Array:
        return self.centres[disc] + self.radii[disc] * np.array([math.cos(angle), math.sin(angle)])

    def _inside_another(self, point: Array, disc: int) -> bool:
        inside = np.hypot(*(point - self.centres).T) < self.radii - TOUCH
        inside[disc] = False
        return bool(inside.any())

    def _tangent_angles(self, point: Array, disc: int) -> tuple[float, float]:
        offset = point - self.centres[disc]
        theta = math.atan2(offset[1], offset[0])
        spread = math.acos(min(1.0, self.radii[disc] / float(np.hypot(*offset))))
        return theta + spread, theta - spread

    def _node(self, disc: int, angle: float) -> int | None:
        """A new node on ``disc`` at ``angle``, unless another disc covers it."""
        point = self._point(disc, angle)
        if self._inside_another(point, disc):
            return None
        self.nodes.append(_Node(point, disc, angle % TAU))
        node = len(self.nodes) - 1
        self.edges[node] = []
        self._of_disc.setdefault(disc, []).append(node)
        return node

    def _tangents(self, end: int, disc: int) -> None:
        for angle in self._tangent_angles(self.nodes[end].point, disc):
            self._link(end, self._node(disc, angle))

    def _link(self, a: int | None, b: int | None) -> None:
        if a is None or b is None:
            return
        if not clear(self.nodes[a].point, self.nodes[b].point, self.centres, self.radii):
            return
        length = float(np.hypot(*(self.nodes[a].point - self.nodes[b].point)))
        self.edges[a].append((b, length, None))
        self.edges[b].append((a, length, None))

    def _blocked(self, disc: int, start: float, sweep: float) -> bool:
        """Another disc covers part of the counter-clockwise arc (start, sweep) of ``disc``."""
        return any(overlaps(start, sweep, interval) for interval in self._covers[disc])

    def _link_arcs(self, disc: int) -> list[int]:
        """Join each node of ``disc`` to its counter-clockwise neighbour by the arc between
        them, where no other disc covers it; the nodes of ``disc`` by angle."""
        self._check_budget()
        on = sorted(self._of_disc.get(disc, []), key=lambda n: self.nodes[n].angle)
        for a, b in zip(on, on[1:] + on[:1], strict=True):
            sweep = (self.nodes[b].angle - self.nodes[a].angle) % TAU
            if a == b or self._blocked(disc, self.nodes[a].angle, sweep):
                continue
            self.edges[a].append((b, self.radii[disc] * sweep, sweep))
            self.edges[b].append((a, self.radii[disc] * sweep, -sweep))
        return on

    def _arcs_into(self, disc: int, angle: float) -> list[tuple[int, float]]:
        """The nodes of ``disc`` on either side of ``angle`` whose arc to it is clear, each
        with the arc's signed sweep towards ``angle``."""
        on = self._on[disc]
        if not on:
            return []
        angles = [self.nodes[n].angle for n in on]
        after = int(np.searchsorted(angles, angle % TAU)) % len(on)
        into = []
        before_sweep = (angle - self.nodes[on[after - 1]].angle) % TAU
        if not self._blocked(disc, self.nodes[on[after - 1]].angle, before_sweep):
            into.append((on[after - 1], before_sweep))
        after_sweep = (self.nodes[on[after]].angle - angle) % TAU
        if not self._blocked(disc, angle % TAU, after_sweep):
            into.append((on[after], -after_sweep))
        return into

    def _search(self) -> tuple[list[float], list[tuple[int, float | None]]]:
        """Dijkstra from the start: each node's distance and (previous node, sweep of the edge
        from it: None for a segment)."""
        distance = [math.inf] * len(self.nodes)
        previous: list[tuple[int, float | None]] = [(-1, None)] * len(self.nodes)
        distance[0] = 0.0
        queue = [(0.0, 0)]
        settled = 0
        while queue:
            d, n = heapq.heappop(queue)
            if d > distance[n]:
                continue
            settled += 1
            if settled % SEARCH_CHECK == 0:
                self._check_budget()
            for m, length, sweep in self.edges[n]:
                if d + length < distance[m]:
                    distance[m], previous[m] = d + length, (n, sweep)
                    heapq.heappush(queue, (d + length, m))
        return distance, previous

    def _path(self, node: int) -> list[tuple[int, float | None]]:
        """The nodes from the start to ``node``, each with the sweep of the edge into it."""
        path = [(node, self.previous[node][1])]
        while path[-1][0] != 0:
            before = self.previous[path[-1][0]][0]
            path.append((before, self.previous[before][1]))
        path[-1] = (0, None)
        return path[::-1]

    def _way(self, target: Array, length: float, path: list[tuple[int, float | None]]) -> Way:
        """The way along ``path`` (node -1: the target's tangent point), then straight to
        ``target``."""
        arcs: list[Arc] = []
        waypoints: list[Array] = []
        if self.start is not self.origin:
            waypoints.append(self.start)
            length += float(np.hypot(*(self.start - self.origin)))
        for (a, _), (_, sweep) in zip(path, path[1:], strict=False):
            if sweep is None or abs(sweep) < TOUCH:
                continue
            disc = self.nodes[a].disc
            arc = Arc(
                tuple(self.centres[disc]), float(self.radii[disc]), self.nodes[a].angle, sweep
            )
            arcs.append(arc)
            waypoints += arc.corners(self.max_turn)
        waypoints.append(target)
        return Way(self.origin, target, tuple(arcs), length, "", tuple(waypoints))
