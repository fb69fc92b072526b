"""The recorder: every message of the namespace into an MCAP session file.

Each topic of the table is read with a queue (``queue`` samples waiting at most), so no
sample is dropped unless the writer falls that far behind, and then the loss is counted
(``overflowed.<topic>``) and written into the file (its ``DROPPED`` metadata, which
``parsimony info`` shows). Each message is written on the channel of its key with the
project's schema, log time from its stamp (``record.session_file``), and beside it in
Foxglove's well-known schemas (``scenes.foxglove_views``: images as ``foxglove.RawImage``,
frames as ``foxglove.FrameTransforms``, obstacles and the robot of the profile's description
as ``foxglove.SceneUpdate``, markers on the image as ``foxglove.ImageAnnotations``), so that
Foxglove's 3D, Image and Plot panels open the file as it is. ``keys`` limits the recording to
topics whose names match one of its comma-separated ``fnmatch`` patterns. A message stamped
far outside the session (``record.session_span``: a wall-clock stamp among simulated ones) is
recorded, counted (``outside.<topic>``) and said once per topic. A message that never reached
the recorder (Zenoh drops a sample when a publisher's queue is full) is seen by the gap it leaves
in its publisher's ``seq``: the gaps of a topic less the samples the recorder itself dropped or
refused are counted (``missed.<topic>``) and written into the file beside the recorder's losses.

The current chunk is flushed every ``flush_s`` (SIGKILL loses at most that much and what
waits); a clean stop writes all that waits, then the file's footer and index. A recorder stops
after everything else (its role is ``recorder``), however long its backlog takes. A file that
cannot be written (a full disk) stops the recorder for good, exit ``EXIT_FOR_GOOD``, with the
error and how many messages the file holds: ``parsimony record --recover`` keeps every
complete chunk.
"""

from __future__ import annotations

import fnmatch
import logging
from pathlib import Path

from components.params import Param, ParamError, load_robot
from components.process_entry import run_component
from components.pubsub import Input
from components.runtime import Component, Node
from messages import topics
from messages.header import Header
from record.session_file import DROPPED, SessionWriter, stamp_of
from record.session_span import Span, inside, outside_line
from scenes.foxglove_views import Viewer
from wbc.robot import MobileManipulator

log = logging.getLogger("components")

QUEUE = 10_000
"""Samples of one topic that may wait for the writer."""


class Recorder(Component):
    """Every topic in, one MCAP file out."""

    reads = tuple(Input(topic, queue=QUEUE) for topic in topics.TOPICS.values())
    writes = ()
    params = (
        Param("path", str, "session.mcap", doc="the MCAP file to write"),
        Param("keys", str, "*", doc="comma-separated patterns of the topic names to record"),
        Param("flush_s", float, 0.25, low=0.05, high=60.0, doc="chunk flush period, s"),
        Param("views", bool, True, doc="also write Foxglove's well-known schemas"),
    )

    def __init__(self, node: Node) -> None:
        super().__init__(node)
        path = Path(str(node.params["path"]))
        viewer = Viewer(self._robot(node))
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            self.writer = SessionWriter(path, viewer=viewer)
        except OSError as error:
            raise ParamError(f"path: cannot write {path}: {error}") from error
        patterns = [p.strip() for p in str(node.params["keys"]).split(",") if p.strip()]
        self.path = path
        self.failed = False
        node.counters["written"] = 0
        self.inputs = [
            node.subscribe(topic, self._writer_of(topic.name, topic.key(node.namespace)))
            for topic in topics.TOPICS.values()
            if any(fnmatch.fnmatch(topic.name, pattern) for pattern in patterns)
        ]
        self.dropped: dict[str, int] = {}
        self.last_seq: dict[tuple[str, str], int] = {}
        """The ``seq`` of the last message of each topic and source."""
        self.gaps: dict[str, int] = {}
        """The messages of each topic its sources' ``seq`` skipped."""
        self.span = Span()
        node.timer(node.params["flush_s"], lambda: self._writing(self._flush))

    @staticmethod
    def _robot(node: Node) -> MobileManipulator | None:
        """The profile's robot, which the file draws (none: its bases and end effectors)."""
        if node.profile.robot is None or not node.params["views"]:
            return None
        return load_robot(node.profile.robot)

    def _writer_of(self, name: str, key: str):
        def write(message) -> None:
            if self._writing(self.writer.write, key, message, views=self.node.params["views"]):
                self.node.counters["written"] += 1
                self._place(name, stamp_of(message))
                self._follow(name, getattr(message, "header", None))

        return write

    def _place(self, name: str, stamp_ns: int) -> None:
        """Count a stamp into the session's span; one far outside it is counted
        (``outside.<topic>``) and said, once per topic."""
        self.span.add(stamp_ns)
        session = self.span.session()
        if inside(stamp_ns, session):
            return
        counter = f"outside.{name}"
        if counter not in self.node.counters:
            log.warning(
                "%s: recorded, but %s; info, replay and report leave it out",
                self.node.name,
                outside_line({name: (1, stamp_ns)}, session),
            )
        self.node.count(counter)

    def _follow(self, name: str, header: Header | None) -> None:
        """Add to the gaps of ``name`` the messages its source published between the last one
        and this one. A ``seq`` that goes back is a publisher started anew (a restarted
        component), not a loss."""
        if header is None:
            return
        key = (name, header.source)
        last = self.last_seq.get(key)
        self.last_seq[key] = header.seq
        if last is not None and header.seq > last + 1:
            self.gaps[name] = self.gaps.get(name, 0) + header.seq - last - 1

    def _missed(self) -> None:
        """``missed.<topic>``: its gaps less what the recorder dropped or refused itself (a gap
        is seen when the next message is handled, so it may trail the drop a while)."""
        counters = self.node.counters
        for name, gaps in self.gaps.items():
            own = counters.get(f"overflowed.{name}", 0) + counters.get(f"rejected.{name}", 0)
            if gaps > own:
                counters[f"missed.{name}"] = gaps - own

    def _writing(self, operation, *args, **kwargs) -> bool:
        """Run a write of the file; on an OSError stop for good (once), saying why."""
        if self.failed:
            return False
        try:
            operation(*args, **kwargs)
            return True
        except OSError as error:
            self.failed = True
            self.node.fail(
                f"cannot write {self.path}: {error}; stopping with "
                f"{self.node.counters['written']} messages written, the file recovers "
                f"to its last complete chunk (parsimony record --recover "
                f"{self.path} OUT)"
            )
            return False

    def _flush(self) -> None:
        """The chunk to the file, and what was lost since the last flush, if anything (the
        file's ``DROPPED`` metadata)."""
        self._missed()
        dropped = {
            k: v
            for k, v in self.node.counters.items()
            if k.startswith(("overflowed.", "overwritten.", "missed.")) and v
        }
        if dropped != self.dropped:
            self.writer.metadata(DROPPED, dropped)
            self.dropped = dropped
        self.writer.flush()

    def shutdown(self) -> None:
        """Write what still waits, what was lost, then the footer: the file is whole."""
        for subscription in self.inputs:
            subscription.drain()
        self._writing(self._flush)
        self._writing(self.writer.close)


if __name__ == "__main__":
    run_component(Recorder)
