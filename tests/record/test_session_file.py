"""record.session_file on real MCAP files: round trips, the mcap package's own reader, files
cut short as a recorder killed by SIGKILL leaves them, and their recovery."""

from __future__ import annotations

import importlib.util
import json
import math
import random
import struct
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
from mcap.exceptions import McapError
from mcap.reader import make_reader
from pydantic import BaseModel

from messages import topics
from messages.camera import CameraFrame
from messages.clock import Clock
from messages.header import Header
from messages.state import RobotState
from record.session_file import CARRIER, DROPPED, Entry, SessionWriter
from record.session_reader import info, read_session, recover
from tests.processes import parsimony
from vision.images import jpeg

NAMESPACE = "lab/robot1"
TOPIC_OF_TYPE = {topic.type: topic for topic in topics.TOPICS.values()}


def _load_examples() -> tuple[BaseModel, ...]:
    """tests/messages/message_examples.py: one valid message of every wire type."""
    path = Path(__file__).parents[1] / "messages" / "message_examples.py"
    spec = importlib.util.spec_from_file_location("record_message_examples", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.EXAMPLES


EXAMPLES = [m for m in _load_examples() if type(m) in TOPIC_OF_TYPE]


def key_of(message: BaseModel) -> str:
    return TOPIC_OF_TYPE[type(message)].key(NAMESPACE)


def header(stamp_ns: int, seq: int = 0) -> Header:
    return Header(stamp_ns=stamp_ns, frame="world", seq=seq, source="test")


def state(stamp_ns: int, seq: int = 0, base_x: float = 1.0) -> RobotState:
    return RobotState(
        header=header(stamp_ns, seq),
        base_pose=(base_x, 2.0, 0.3),
        arm_joints=(0.1, -0.2, 0.3, -0.4, 0.5),
        end_effector=(1.0, 0, 0, 0, 0, 0, 0, 0),
        valid=True,
        age_s=0.0,
    )


def image(stamp_ns: int, encoding: str = "rgb8") -> CameraFrame:
    width, height = 64, 48
    size = width * height * (1 if encoding == "mono8" else 3)
    pixels = random.Random(stamp_ns).randbytes(size)
    return CameraFrame.model_validate(
        {
            "header": header(stamp_ns),
            "encoding": encoding,
            "width": width,
            "height": height,
            "data": pixels,
            "intrinsics": {"fx": 80.0, "fy": 80.0, "cx": 31.5, "cy": 23.5},
        }
    )


def test_every_topic_type_reads_back_equal_in_log_time_order(tmp_path: Path) -> None:
    assert {type(m) for m in EXAMPLES} == set(TOPIC_OF_TYPE), "an example of every topic"
    path = tmp_path / "session.mcap"
    written = [(key_of(m), 1_000 + 10 * i, m) for i, m in enumerate(EXAMPLES * 2)]
    with SessionWriter(path) as writer:
        for key, log_time, message in reversed(written):  # written late-first
            writer.write(key, message, log_time)
    recorded = list(read_session(path))
    assert [(r.key, r.log_time_ns, r.message) for r in recorded] == written
    assert [r.topic_name for r in recorded] == [TOPIC_OF_TYPE[type(m)].name for *_, m in written]


def test_log_time_is_the_stamp_unless_given(tmp_path: Path) -> None:
    path = tmp_path / "session.mcap"
    with SessionWriter(path) as writer:
        writer.write(topics.ROBOT_STATE.key(NAMESPACE), state(5_000))
        writer.write(topics.SIM_CLOCK.key(NAMESPACE), Clock(stamp_ns=7_000))
        writer.write(topics.ROBOT_STATE.key(NAMESPACE), state(9_000), log_time_ns=3_000)
    assert [r.log_time_ns for r in read_session(path)] == [3_000, 5_000, 7_000]


def jpeg_image(stamp_ns: int) -> CameraFrame:
    grey = np.random.default_rng(stamp_ns).integers(0, 256, (48, 64), dtype=np.uint8)
    return CameraFrame.model_validate(
        {
            "header": header(stamp_ns),
            "encoding": "jpeg",
            "width": 64,
            "height": 48,
            "data": jpeg(grey, 90),
            "intrinsics": {"fx": 80.0, "fy": 80.0, "cx": 31.5, "cy": 23.5},
        }
    )


def test_with_views_each_image_is_stored_once_and_reads_back_exactly(tmp_path: Path) -> None:
    frames = [image(2, "rgb8"), image(3, "mono8"), jpeg_image(4), jpeg_image(5)]
    path = tmp_path / "session.mcap"
    with SessionWriter(path) as writer:
        for frame in frames:
            writer.write(topics.CAMERA_IMAGE.key(NAMESPACE), frame, views=True)
    assert [r.message for r in read_session(path) if r.message is not None] == frames
    # The pixels are in the views alone: the frames' JSON is a few hundred bytes each.
    by_key = {c["key"]: c for c in info(path)["channels"]}
    key = topics.CAMERA_IMAGE.key(NAMESPACE)
    assert by_key[key]["bytes"] < 500 * len(frames)
    assert by_key[f"{key}/foxglove"]["bytes"] < sum(len(f.data) for f in frames) + 200
    with path.open("rb") as stream:
        channels = make_reader(stream).get_summary().channels.values()
    assert {c.topic: c.metadata.get(CARRIER) for c in channels}[key] == f"{key}/foxglove"


def test_floats_and_images_survive_bit_for_bit(tmp_path: Path) -> None:
    awkward = (0.1 + 0.2, 1 / 3, -0.0, 5e-324, 1.7976931348623157e308)
    message = RobotState(
        header=header(1),
        base_pose=awkward[:3],
        arm_joints=awkward,
        end_effector=(math.cos(0.1), 0, 0, math.sin(0.1), 0, 0, 0, 0),
        valid=False,
        age_s=2.0 / 3.0,
    )
    frames = [image(2, "rgb8"), image(3, "bgr8"), image(4, "mono8")]
    path = tmp_path / "session.mcap"
    with SessionWriter(path) as writer:
        writer.write(topics.ROBOT_STATE.key(NAMESPACE), message)
        for frame in frames:
            writer.write(topics.CAMERA_IMAGE.key(NAMESPACE), frame)
    back, *images = [r.message for r in read_session(path)]

    def bits(values: tuple[float, ...]) -> bytes:
        return struct.pack(f"<{len(values)}d", *values)

    assert bits(back.arm_joints) == bits(awkward)
    assert bits(back.base_pose) == bits(awkward[:3])
    assert bits(back.end_effector) == bits(message.end_effector)
    assert images == frames
    assert [i.data for i in images] == [f.data for f in frames]


def test_info_counts_what_was_written_and_every_channel_has_its_schema(tmp_path: Path) -> None:
    path = tmp_path / "session.mcap"
    with SessionWriter(path) as writer:
        for i in range(101):  # 100 Hz for 1 s
            writer.write(topics.ROBOT_STATE.key(NAMESPACE), state(1_000_000_000 + i * 10_000_000))
        for i in range(11):  # 10 Hz
            writer.write(topics.SIM_CLOCK.key(NAMESPACE), Clock(stamp_ns=1_000_000_000 + i * 10**8))
        writer.write(topics.CAMERA_IMAGE.key(NAMESPACE), image(1_500_000_000))
    found = info(path)
    assert found["complete"] is True
    assert found["messages"] == 113
    assert found["bytes"] == path.stat().st_size
    assert (found["start_ns"], found["end_ns"], found["duration_s"]) == (10**9, 2 * 10**9, 1.0)
    by_key = {c["key"]: c for c in found["channels"]}
    state_channel = by_key[topics.ROBOT_STATE.key(NAMESPACE)]
    assert (state_channel["schema"], state_channel["messages"]) == ("RobotState", 101)
    assert state_channel["rate_hz"] == 100.0
    assert by_key[topics.SIM_CLOCK.key(NAMESPACE)]["rate_hz"] == 10.0
    assert by_key[topics.CAMERA_IMAGE.key(NAMESPACE)]["messages"] == 1
    for channel in found["channels"]:
        assert channel["schema_encoding"] == "jsonschema" and channel["encoding"] == "json"
        assert channel["schema_bytes"] > 100


def test_the_mcap_package_reads_the_file_with_every_schema(tmp_path: Path) -> None:
    path = tmp_path / "session.mcap"
    with SessionWriter(path) as writer:
        for message in EXAMPLES:
            writer.write(key_of(message), message)
        writer.write_raw(
            Entry(
                f"{NAMESPACE}/notes",
                "Note",
                "jsonschema",
                b'{"type":"object"}',
                "json",
                b'{"text":"hello"}',
            ),
            5,
        )
    with path.open("rb") as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        read = list(reader.iter_messages())
    assert len(read) == summary.statistics.message_count == len(EXAMPLES) + 1
    expected = {key_of(m): type(m).__name__ for m in EXAMPLES} | {f"{NAMESPACE}/notes": "Note"}
    for schema, channel, message in read:
        assert schema is not None and channel.schema_id in summary.schemas
        assert schema.name == expected[channel.topic]
        assert json.loads(schema.data)["type"] == "object"
        assert isinstance(json.loads(message.data), dict)
    camera_schema = next(s for s in summary.schemas.values() if s.name == "CameraFrame")
    data_field = json.loads(camera_schema.data)["properties"]["data"]
    assert data_field["contentEncoding"] == "base64"
    # The view channel reads back as such: no project type, its message None.
    note = next(r for r in read_session(path) if r.key.endswith("/notes"))
    assert (note.topic_name, note.message, note.log_time_ns) == (None, None, 5)


def write_flushed(path: Path, count: int, flush_every: int) -> tuple[SessionWriter, list[int]]:
    """``count`` messages, a flush every ``flush_every``, not closed: the writer and the file's
    size after each flush (entry ``k``: ``k * flush_every`` messages in complete chunks)."""
    writer = SessionWriter(path)
    sizes = [path.stat().st_size]
    for i in range(count):
        writer.write(topics.ROBOT_STATE.key(NAMESPACE), state(10**9 + i * 10**7, seq=i))
        if i % 10 == 9:
            writer.write(topics.CAMERA_IMAGE.key(NAMESPACE), image(10**9 + i * 10**7))
        if (i + 1) % flush_every == 0:
            writer.flush()
            sizes.append(path.stat().st_size)
    return writer, sizes


def states_in(path: Path) -> list[int]:
    return [r.message.header.seq for r in read_session(path) if r.topic_name == "robot/state"]


def test_a_file_cut_mid_chunk_reads_every_complete_chunk_and_recovers(tmp_path: Path) -> None:
    path = tmp_path / "killed.mcap"
    writer, sizes = write_flushed(path, count=200, flush_every=20)
    middle = len(sizes) // 2
    data = path.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: sizes[middle] + 100])  # 100 bytes into the next chunk
    writer.close()
    with cut.open("rb") as stream:
        with pytest.raises(McapError):  # no footer: the seeking reader gives up
            list(make_reader(stream).iter_messages())
    saved = middle * 20
    assert states_in(cut) == list(range(saved))
    found = info(cut)
    assert found["complete"] is False
    assert found["messages"] == saved + saved // 10
    whole = tmp_path / "whole.mcap"
    assert recover(cut, whole) == found["messages"]
    with whole.open("rb") as stream:
        reader = make_reader(stream)
        assert reader.get_summary().statistics.message_count == found["messages"]
        assert sum(1 for _ in reader.iter_messages()) == found["messages"]
    assert list(read_session(whole)) == list(read_session(cut))
    assert info(whole)["complete"] is True


def test_a_writer_stopped_without_close_loses_only_what_came_after_its_flush(
    tmp_path: Path,
) -> None:
    path = tmp_path / "killed.mcap"
    writer, sizes = write_flushed(path, count=95, flush_every=30)
    snapshot = tmp_path / "snapshot.mcap"
    snapshot.write_bytes(path.read_bytes())  # the file as SIGKILL would leave it
    writer.close()
    assert states_in(snapshot) == list(range(90))
    assert states_in(path) == list(range(95))


def test_a_cut_anywhere_reads_without_error_and_never_loses_a_complete_chunk(
    tmp_path: Path,
) -> None:
    path = tmp_path / "small.mcap"
    with SessionWriter(path) as writer:
        for i in range(30):
            writer.write(topics.SIM_CLOCK.key(NAMESPACE), Clock(stamp_ns=i))
            if i % 3 == 2:
                writer.flush()
    data = path.read_bytes()
    cut = tmp_path / "cut.mcap"
    counts = []
    for end in range(0, len(data) + 1, 7):
        cut.write_bytes(data[:end])
        counts.append(len(list(read_session(cut))))
    assert counts == sorted(counts)
    assert counts[-1] == 30 and set(counts) <= set(range(0, 31, 3))


def test_a_file_that_is_no_mcap_is_an_error_not_an_empty_session(tmp_path: Path) -> None:
    path = tmp_path / "not.mcap"
    path.write_bytes(b"this is not an MCAP file at all")
    with pytest.raises(McapError):
        list(read_session(path))


def test_recover_refuses_to_overwrite_its_source(tmp_path: Path) -> None:
    path = tmp_path / "session.mcap"
    SessionWriter(path).close()
    with pytest.raises(ValueError, match="overwritten"):
        recover(path, path)


def test_what_the_recorder_lost_is_in_the_file_and_info_shows_it(tmp_path: Path) -> None:
    path = tmp_path / "lossy.mcap"
    with SessionWriter(path) as writer:
        writer.write(topics.ROBOT_STATE.key(NAMESPACE), state(5_000))
        writer.metadata(DROPPED, {"overflowed.camera/image": 3})
        writer.metadata(DROPPED, {"overflowed.camera/image": 7, "overwritten.sim/clock": 2})
    assert info(path)["dropped"] == {"overflowed.camera/image": 7, "overwritten.sim/clock": 2}
    recovered = tmp_path / "recovered.mcap"
    recover(path, recovered)  # what was lost is still said of the recovered file
    assert info(recovered)["dropped"] == info(path)["dropped"]
    shown = parsimony("info", str(path))
    assert "lost by the recorder: 7 (overflowed.camera/image), 2 (overwritten.sim/clock)" in (
        shown.stdout
    )


def test_chunks_that_overlap_in_time_read_back_in_log_time_order(tmp_path: Path) -> None:
    """A recorder that falls behind writes late messages into later chunks: the streamed read
    gives what mcap's own indexed reader gives in log-time order, images put back."""
    rng = random.Random(7)
    times = [50_000 + 1_000 * i + rng.randrange(-30_000, 30_000) for i in range(600)]  # unordered
    path = tmp_path / "session.mcap"
    with SessionWriter(path, chunk_size=4_000) as writer:  # many small chunks
        for log_time in times:
            writer.write(topics.ROBOT_STATE.key(NAMESPACE), state(log_time), log_time)
            if log_time % 7 == 0:
                writer.write(topics.CAMERA_IMAGE.key(NAMESPACE), image(log_time), views=True)
    with path.open("rb") as stream:
        indexed = [
            (c.topic, m.log_time)
            for _, c, m in make_reader(stream).iter_messages(log_time_order=True)
        ]
    streamed = list(read_session(path))
    assert [(r.key, r.log_time_ns) for r in streamed] == indexed
    assert [r.message.header.stamp_ns for r in streamed if r.message is not None] == sorted(
        times + [t for t in times if t % 7 == 0]
    )


def test_only_the_topics_asked_for_are_read(tmp_path: Path) -> None:
    path = tmp_path / "session.mcap"
    with SessionWriter(path) as writer:
        for stamp in range(1, 20):
            writer.write(topics.ROBOT_STATE.key(NAMESPACE), state(stamp))
            writer.write(topics.CAMERA_IMAGE.key(NAMESPACE), image(stamp), views=True)
    only = list(read_session(path, only={topics.ROBOT_STATE.name}))
    assert [r.topic_name for r in only] == [topics.ROBOT_STATE.name] * 19
    frames = [r.message for r in read_session(path, only={topics.CAMERA_IMAGE.name})]
    assert frames == [image(stamp) for stamp in range(1, 20)]  # still put back from the views


def peak_read_bytes(path: Path) -> int:
    """The most memory Python held at once while reading every message of ``path``."""
    tracemalloc.start()
    try:
        for _ in read_session(path):
            pass
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_reading_holds_the_same_memory_whatever_the_length_of_the_file(tmp_path: Path) -> None:
    """A session four times as long (images and states, many chunks) is read holding no more
    memory than a short one: the read is streamed, not gathered and sorted."""
    peaks = []
    for frames in (60, 240):
        path = tmp_path / f"{frames}.mcap"
        with SessionWriter(path, chunk_size=64 * 1024) as writer:
            for stamp in range(1, frames + 1):
                writer.write(topics.CAMERA_IMAGE.key(NAMESPACE), image(stamp * 1_000), views=True)
                writer.write(topics.ROBOT_STATE.key(NAMESPACE), state(stamp * 1_000))
        peaks.append(peak_read_bytes(path))
    assert peaks[1] < 1.3 * peaks[0], peaks  # held in full, it would be 4 times
