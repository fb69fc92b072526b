"""The dataflow of a profile, derived from what each component declares it reads and writes.

Every enabled component's module is imported and its ``Component`` subclass asked for
``reads`` and ``writes`` (``components.runtime.Component``); a component on simulated time
also reads ``sim/clock`` (``Profile.clock_of``); a profile's ``remap`` renames what a
component reads and writes (``ComponentSpec.topic``); its ``params`` are checked against what
the class declares (names, types, bounds, choices), so a value no component could take is
refused before anything starts. Nothing is started.
"""

from __future__ import annotations

import importlib
import inspect
from dataclasses import dataclass
from pathlib import Path

from components.params import ParamError, Parameters
from components.pubsub import Input
from components.runtime import Component
from messages import topics
from profiles.profile import ComponentSpec, Profile, ProfileError


@dataclass(frozen=True)
class ComponentNode:
    """One process of the graph."""

    name: str
    module: str
    role: str
    reads: tuple[Input, ...]
    writes: tuple[topics.Topic, ...]


@dataclass(frozen=True)
class Dataflow:
    """Which process publishes and which subscribes to which key of the namespace."""

    namespace: str
    components: tuple[ComponentNode, ...]

    def topics(self) -> list[str]:
        """Every topic read or written, in the order of the topic table."""
        used = {i.topic.name for c in self.components for i in c.reads}
        used |= {t.name for c in self.components for t in c.writes}
        return [name for name in topics.TOPICS if name in used]

    def writers(self, topic: str) -> list[str]:
        return [c.name for c in self.components if topic in {t.name for t in c.writes}]

    def readers(self, topic: str, waiting: bool = False) -> list[str]:
        """The components that read ``topic`` (``waiting``: but a recorder)."""
        return [
            c.name
            for c in self.components
            if topic in {i.topic.name for i in c.reads} and not (waiting and c.role == "recorder")
        ]

    def read_never_written(self) -> list[str]:
        """Topics some component waits for that no component of the profile publishes (a
        recorder, which takes whatever comes, waits for none)."""
        return [
            name
            for name in self.topics()
            if not self.writers(name) and self.readers(name, waiting=True)
        ]

    def warnings(self) -> list[str]:
        """One line per topic read and never written."""
        return [
            f"warning: {self.key(name)} is read by {', '.join(self.readers(name))} and "
            "written by no component of the profile"
            for name in self.read_never_written()
        ]

    def key(self, topic: str) -> str:
        return topics.TOPICS[topic].key(self.namespace)

    def to_text(self) -> str:
        """One block per component, then one line per topic: writers -> key -> readers."""
        lines = []
        for c in self.components:
            lines.append(f"{c.name} ({c.module}, {c.role})")
            if c.reads:
                lines.append("  reads  " + ", ".join(i.describe() for i in c.reads))
            if c.writes:
                lines.append("  writes " + ", ".join(t.name for t in c.writes))
        lines.append("topics")
        for name in self.topics():
            writers = ", ".join(self.writers(name)) or "(nobody)"
            readers = ", ".join(self.readers(name)) or "(nobody)"
            lines.append(f"  {writers} -> {self.key(name)} -> {readers}")
        return "\n".join(lines)

    def to_dot(self) -> str:
        """The graph in Graphviz's DOT language: components as boxes, keys as ellipses."""
        lines = [f'digraph "{self.namespace}" {{', "  rankdir=LR;"]
        unwritten = self.read_never_written()
        for c in self.components:
            lines.append(f'  "{c.name}" [shape=box, label="{c.name}\\n{c.module}"];')
        for name in self.topics():
            style = ", style=dashed" if name in unwritten else ""
            lines.append(f'  "{self.key(name)}" [shape=ellipse{style}];')
            lines += [f'  "{w}" -> "{self.key(name)}";' for w in self.writers(name)]
            lines += [f'  "{self.key(name)}" -> "{r}";' for r in self.readers(name)]
        lines.append("}")
        return "\n".join(lines)

    def to_json(self) -> dict:
        return {
            "namespace": self.namespace,
            "components": [
                {
                    "name": c.name,
                    "module": c.module,
                    "role": c.role,
                    "reads": [{"topic": i.topic.name, "queue": i.queue} for i in c.reads],
                    "writes": [t.name for t in c.writes],
                }
                for c in self.components
            ],
            "topics": {
                name: {
                    "key": self.key(name),
                    "writers": self.writers(name),
                    "readers": self.readers(name),
                }
                for name in self.topics()
            },
            "read_never_written": self.read_never_written(),
        }


def component_class(spec: ComponentSpec) -> type[Component]:
    """The ``Component`` subclass that ``spec``'s module defines and runs."""
    module = importlib.import_module(spec.module_path)
    found = [
        value
        for value in vars(module).values()
        if inspect.isclass(value)
        and issubclass(value, Component)
        and not inspect.isabstract(value)
        and value.__module__ == module.__name__
    ]
    if len(found) != 1:
        names = [cls.__name__ for cls in found]
        raise LookupError(f"{spec.module_path}: expected one Component subclass, found {names}")
    return found[0]


def dataflow(profile: Profile, path: Path | str = "profile") -> Dataflow:
    """The graph of the profile's enabled components; ``ProfileError`` naming ``path`` and the
    field for a parameter the component would refuse."""
    nodes = []
    for spec in profile.start_order():
        cls = component_class(spec)
        try:
            Parameters(cls.params, spec.params)
        except ParamError as error:
            index = profile.components.index(spec)
            raise ProfileError(
                f"{path}: invalid profile\n  components[{index}] ({spec.name}).params.{error}"
            ) from None
        reads = tuple(Input(spec.topic(i.topic), i.queue) for i in cls.reads)
        if profile.clock_of(spec, topics.SIM_CLOCK in cls.writes) == "sim":
            reads += (Input(topics.SIM_CLOCK),)
        writes = tuple(spec.topic(t) for t in cls.writes)
        nodes.append(ComponentNode(spec.name, spec.module, spec.role, reads, writes))
    return Dataflow(profile.namespace, tuple(nodes))
