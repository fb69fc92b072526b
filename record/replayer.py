"""The replay engine: a recorded session back into Zenoh with its recorded timing.

Messages go out as recorded, headers unchanged, spaced by their recorded log times divided by
the rate (those of one time sensors first: camera, joints, odometry), streamed from the file
(``record.session_reader.read_groups``). ``clock`` also publishes ``sim/clock`` at the recorded
times; ``lockstep`` waits after each camera frame and odometry message until the live tracker
and estimator have answered it (``messages.lockstep``, the simulator's own handshake). Keys
(``record.replay_keys``) pause, step, change the rate and quit; progress goes to stderr.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import zenoh

from messages import codec, topics
from messages.clock import Clock
from messages.lockstep import AnswerStamps
from record.replay_keys import QUIT, RIGHT, KeyReader
from record.session_file import Recorded
from record.session_reader import info, read_groups

SENSORS = ("camera/image", "arm/joint_states", "base/odometry")
"""What ``--sensors`` replays: the inputs a robot's drivers and camera give. Messages of one
recorded time go out in this order, then the others in file order: the simulator publishes a
step's frame, joints and odometry so, and the estimator pairs each odometry with the joints
before it; a file's order of equal times is only the order the recorder wrote them in, which
differs when it falls behind."""
CLOCK_PERIOD_NS = 10_000_000
"""``--clock`` publishes sim/clock at most this often (recorded time)."""
RATE_LIMITS = (1 / 64, 64.0)
"""The rates the ``+`` and ``-`` keys stay within."""
ANSWERS = {
    topics.CAMERA_IMAGE.name: topics.FRAME_ANSWERS,
    topics.BASE_ODOMETRY.name: (topics.ROBOT_STATE,),
}
"""What ``--lockstep`` waits for after a message, stamped with its stamp: a camera frame is
answered by the tracker's markers and the estimator's obstacles (as the simulator's lockstep
waits for them), odometry by the estimator's state."""
ANSWERING = {topic.name: topic for answers in ANSWERS.values() for topic in answers}
"""The topics that carry answers, by name."""
ANSWER_TIMEOUT_S = 1.0
"""Host seconds ``--lockstep`` waits for an answer before it goes on (said and counted), unless
``--answer-timeout`` says otherwise."""
KEYS_HELP = "space: pause/play, s or right arrow: step, +/-: rate, q: quit"


def sending_rank(topic_name: str) -> int:
    """Where a message goes among those of its recorded time: ``SENSORS`` first, in order."""
    return SENSORS.index(topic_name) if topic_name in SENSORS else len(SENSORS)


@dataclass(frozen=True)
class Recording:
    """What a replay sends from a file: the topics it holds that ``wanted`` lets through and
    the log times of their first and last messages (from ``info``: one pass, nothing held);
    ``groups`` streams their messages, one log time at a time, in sending order. Messages
    logged far outside the session (``record.session_span``) are outside every window, so
    never sent; ``outside`` says what they are in one line (None: there are none)."""

    path: Path
    names: frozenset[str]
    start_ns: int
    end_ns: int
    outside: str | None = None
    namespaces: frozenset[str] = frozenset()
    """The namespaces its keys were recorded in."""

    @classmethod
    def of(cls, path: Path, wanted: Callable[[str], bool]) -> Recording:
        """The topics of ``path`` that ``wanted`` lets through, and their span."""
        found = info(path)
        channels = [
            c
            for c in found["channels"]
            if c["topic"] is not None and c["messages"] and wanted(c["topic"])
        ]
        namespaces = frozenset(
            c["key"].removesuffix(topics.TOPICS[c["topic"]].suffix)[:-1] for c in channels
        )
        return cls(
            path,
            frozenset(c["topic"] for c in channels),
            min((c["start_ns"] for c in channels), default=0),
            max((c["end_ns"] for c in channels), default=0),
            found["warning"],
            namespaces,
        )

    def namespace(self) -> str:
        """The one namespace it was recorded in; ``ValueError`` when it holds several."""
        if len(self.namespaces) != 1:
            raise ValueError(
                f"{self.path}: recorded in the namespaces "
                f"{', '.join(sorted(self.namespaces))}: give --namespace"
            )
        return topics.check_namespace(next(iter(self.namespaces)))

    def window(self, start_offset_s: float, duration_s: float | None) -> tuple[int, int]:
        """The log times replayed: from ``start_offset_s`` after the first message, for
        ``duration_s`` (None: to the end), never past the last message."""
        first = self.start_ns + round(start_offset_s * 1e9)
        last = first + round(duration_s * 1e9) if duration_s else self.end_ns
        return first, min(last, self.end_ns)

    def groups(self, first_ns: int, last_ns: int) -> Iterator[list[Recorded]]:
        """The messages of each log time in [first_ns, last_ns], ``SENSORS`` first."""
        for group in read_groups(self.path, self.names):
            log_time = group[0].log_time_ns
            if log_time > last_ns:
                return
            if log_time >= first_ns:
                yield sorted(group, key=lambda r: sending_rank(r.topic_name))


@dataclass
class Pace:
    """The recorded-timing schedule: recorded time ``anchor_ns`` is due at host time
    ``anchor_s`` (``time.monotonic``), later ones ``rate`` times as fast. While ``paused``,
    ``anchor_ns`` is where the replay stands. Every change (pause, resume, rate, a wait)
    re-anchors the schedule where the recorded time stands, so it stays right across them."""

    rate: float
    anchor_ns: int
    anchor_s: float
    paused: bool = False

    def due_s(self, recorded_ns: int) -> float:
        """The host time at which ``recorded_ns`` is due (while playing)."""
        return self.anchor_s + (recorded_ns - self.anchor_ns) / 1e9 / self.rate

    def now_ns(self, now_s: float, upto_ns: int) -> int:
        """Where the recorded time stands at host time ``now_s``, not past ``upto_ns`` (the
        next message, not yet sent)."""
        if self.paused:
            return self.anchor_ns
        return min(upto_ns, self.anchor_ns + round((now_s - self.anchor_s) * self.rate * 1e9))

    def anchor(self, recorded_ns: int, now_s: float) -> None:
        self.anchor_ns, self.anchor_s = recorded_ns, now_s

    def toggle(self, now_s: float, next_ns: int) -> None:
        """Pause where the recorded time stands, or resume from there."""
        self.anchor(self.now_ns(now_s, next_ns), now_s)
        self.paused = not self.paused

    def scale(self, factor: float, now_s: float, next_ns: int) -> None:
        """Multiply the rate by ``factor`` within ``RATE_LIMITS`` (a rate already outside
        them is not moved further out), from where the recorded time stands."""
        low, high = RATE_LIMITS
        rate = min(max(self.rate * factor, min(low, self.rate)), max(high, self.rate))
        self.anchor(self.now_ns(now_s, next_ns), now_s)
        self.rate = rate


class Progress:
    """The progress line on stderr: recorded time / duration, rate, paused, messages sent.
    Redrawn in place on a terminal; elsewhere a line a second and one at every change."""

    def __init__(self, first_ns: int, duration_ns: int) -> None:
        self.first_ns, self.duration_ns = first_ns, duration_ns
        self.in_place = sys.stderr.isatty()
        self.shown_s = -1.0
        self.line_open = False

    def show(self, pace: Pace, recorded_ns: int, sent: int, changed: bool = False) -> None:
        now = time.monotonic()
        if not changed and now - self.shown_s < 1.0:
            return
        self.shown_s = now
        line = (
            f"[replay] {(recorded_ns - self.first_ns) / 1e9:7.2f} / "
            f"{self.duration_ns / 1e9:.2f} s  rate {pace.rate:g}"
            f"{'  paused' if pace.paused else ''}  {sent} messages"
        )
        end = "\x1b[K" if self.in_place else "\n"
        print(("\r" if self.in_place else "") + line, end=end, file=sys.stderr, flush=True)
        self.line_open = self.in_place

    def say(self, text: str) -> None:
        """A line of its own (below the progress line on a terminal)."""
        print(("\n" if self.line_open else "") + f"[replay] {text}", file=sys.stderr, flush=True)
        self.line_open = False


class Answers:
    """The live loop's answers (``ANSWERS``) to the message just sent."""

    def __init__(self, session: zenoh.Session, namespace: str, timeout_s: float) -> None:
        self.timeout_s = timeout_s
        self._stamps = AnswerStamps()
        self._changed = threading.Condition()
        self.timeouts = 0
        self._subscribers = [
            session.declare_subscriber(topic.key(namespace), self._taker(topic))
            for topic in ANSWERING.values()
        ]

    def _taker(self, topic: topics.Topic):
        def take(sample: zenoh.Sample) -> None:
            try:
                stamp = codec.decode(sample.payload.to_bytes(), topic.type).header.stamp_ns
            except codec.DecodeError:
                return  # not an answer the replay can read: it waits for a good one
            with self._changed:
                self._stamps.note(topic.name, stamp)
                self._changed.notify_all()

        return take

    def expect(self) -> None:
        """Forget earlier answers: call before sending a message that is answered."""
        with self._changed:
            self._stamps.forget()

    def wait(self, record: Recorded) -> bool:
        """Until every answer to ``record`` (stamped with its log time) is in, at most
        ``timeout_s``; False (and counted in ``timeouts``) when one did not come."""
        names = [t.name for t in ANSWERS[record.topic_name]]
        with self._changed:
            if self._changed.wait_for(
                lambda: self._stamps.answered(record.log_time_ns, names), self.timeout_s
            ):
                return True
        self.timeouts += 1
        return False


@dataclass(frozen=True)
class Playing:
    """How a replay plays: its ``rate``, its window (``start_offset_s``, ``duration_s``),
    whether it ``loop``s, publishes ``clock``, waits in ``lockstep`` (at most
    ``answer_timeout_s`` for an answer), starts paused."""

    rate: float = 1.0
    start_offset_s: float = 0.0
    duration_s: float | None = None
    loop: bool = False
    clock: bool = False
    lockstep: bool = False
    start_paused: bool = False
    answer_timeout_s: float = ANSWER_TIMEOUT_S


class Player:
    """One replay: the passes over the records, the keys, the progress line."""

    def __init__(
        self,
        playing: Playing,
        session: zenoh.Session,
        namespace: str,
        recording: Recording,
        keys: KeyReader | None,
    ) -> None:
        self.playing, self.keys, self.recording = playing, keys, recording
        self.first_ns, self.last_ns = recording.window(playing.start_offset_s, playing.duration_s)
        self.progress = Progress(self.first_ns, self.last_ns - self.first_ns)
        self.pace = Pace(playing.rate, self.first_ns, time.monotonic(), paused=playing.start_paused)
        self.sent = 0
        """The messages sent in this pass."""
        self.answers = (
            Answers(session, namespace, playing.answer_timeout_s) if playing.lockstep else None
        )
        names = recording.names | ({"sim/clock"} if playing.clock else set())
        block = zenoh.CongestionControl.BLOCK  # a replay waits rather than drop a sample
        self.publishers = {
            name: session.declare_publisher(
                topics.TOPICS[name].key(namespace), congestion_control=block
            )
            for name in names
        }

    def run(self) -> int:
        if self.keys is not None:
            self.progress.say(KEYS_HELP)
        elif self.playing.start_paused:
            self.progress.say("paused: press Enter to start")
            sys.stdin.readline()
            self.pace.paused = False
        while True:
            try:
                sent, quit_asked = self.replay_once()
            except KeyboardInterrupt:
                self.progress.say(f"{self.sent} messages sent (interrupted)")
                raise
            if self.answers is not None and self.answers.timeouts:
                self.progress.say(
                    f"{self.answers.timeouts} messages not answered within "
                    f"{self.answers.timeout_s:g} s"
                )
            self.progress.say(f"{sent} messages sent" + (" (quit)" if quit_asked else ""))
            if quit_asked or not self.playing.loop:
                return 0

    def replay_once(self) -> tuple[int, bool]:
        """One pass over the records at the recorded pace; the number of messages sent and
        whether ``q`` was pressed."""
        pace, clock_ns, sent = self.pace, None, 0
        self.sent = 0
        pace.anchor(self.first_ns, time.monotonic())
        self.progress.show(pace, self.first_ns, sent, changed=True)
        for group in self.recording.groups(self.first_ns, self.last_ns):
            for record in group:
                if not self.wait_until_due(record.log_time_ns, sent):
                    return sent, True
                clock_due = clock_ns is None or record.log_time_ns - clock_ns >= CLOCK_PERIOD_NS
                if self.playing.clock and clock_due:
                    clock_ns = record.log_time_ns
                    self.publish("sim/clock", Clock(stamp_ns=clock_ns))
                self.send(record)
                sent += 1
                self.sent = sent
                if pace.paused:
                    pace.anchor(record.log_time_ns, time.monotonic())
                self.progress.show(pace, record.log_time_ns, sent, changed=pace.paused)
        return sent, False

    def wait_until_due(self, recorded_ns: int, sent: int) -> bool:
        """Wait until ``recorded_ns`` is due, or a step is asked for while paused, following
        the keys; False when ``q`` was pressed."""
        pace = self.pace
        while True:
            now = time.monotonic()
            left_s = None if pace.paused else max(0.0, pace.due_s(recorded_ns) - now)
            if self.keys is None:
                time.sleep(left_s)  # the recorded gap, scaled (never paused without keys)
                return True
            key = self.keys.read(left_s)  # a key already typed is read even when due
            now = time.monotonic()
            if key is None:
                if not pace.paused and pace.due_s(recorded_ns) <= now:
                    return True
                continue
            if key == QUIT:
                return False
            if key in ("s", RIGHT) and pace.paused:
                return True
            if key == " ":
                pace.toggle(now, recorded_ns)
            elif key in ("+", "-"):
                pace.scale(2.0 if key == "+" else 0.5, now, recorded_ns)
            else:
                continue
            self.progress.show(pace, pace.now_ns(now, recorded_ns), sent, changed=True)

    def send(self, record: Recorded) -> None:
        """Publish ``record``; under ``--lockstep`` its answers are waited for, the wait added
        to the schedule as a pause would be."""
        answered = self.answers is not None and record.topic_name in ANSWERS
        if answered:
            self.answers.expect()
        self.publish(record.topic_name, record.message)
        if answered:
            started = time.monotonic()
            if not self.answers.wait(record):
                stamp_s = record.log_time_ns / 1e9
                self.progress.say(
                    f"no answer to {record.topic_name} of {stamp_s:.3f} s "
                    f"in {self.answers.timeout_s:g} s; going on"
                )
            self.pace.anchor_s += time.monotonic() - started

    def publish(self, name: str, message) -> None:
        """Publish as recorded: the header is the recorded one (verbatim)."""
        self.publishers[name].put(codec.encode(message))
