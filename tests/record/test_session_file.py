"""record.session_file on real MCAP files: round trips, the mcap package's own reader, what a
writer stopped without close keeps, and what the recorder lost."""

from __future__ import annotations

import importlib.util
import json
import math
import struct
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from pydantic import BaseModel

from messages import topics
from messages.camera import CameraFrame
from messages.clock import Clock
from messages.state import RobotState
from record.session_file import CARRIER, DROPPED, Entry, SessionWriter, to_json
from record.session_reader import info, read_session, recover
from tests.parsimony.in_process import run_in_process
from tests.record.session_messages import (
    NAMESPACE,
    header,
    image,
    state,
    states_in,
    write_flushed,
)
from vision.images import jpeg

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
    awkward = (0.1 + 0.2, 1 / 3, -0.0, 5e-324, 1.7976931348623157e308, 1e-05, -2.5e-07, 1e22)
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


def test_what_the_recorder_lost_is_in_the_file_and_info_shows_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "lossy.mcap"
    with SessionWriter(path) as writer:
        writer.write(topics.ROBOT_STATE.key(NAMESPACE), state(5_000))
        writer.metadata(DROPPED, {"overflowed.camera/image": 3})
        writer.metadata(DROPPED, {"overflowed.camera/image": 7, "overwritten.sim/clock": 2})
    assert info(path)["dropped"] == {"overflowed.camera/image": 7, "overwritten.sim/clock": 2}
    recovered = tmp_path / "recovered.mcap"
    recover(path, recovered)  # what was lost is still said of the recovered file
    assert info(recovered)["dropped"] == info(path)["dropped"]
    _, shown, _ = run_in_process(["info", str(path)], capsys)
    assert "lost by the recorder: 7 (overflowed.camera/image), 2 (overwritten.sim/clock)" in shown


def test_bytes_nested_in_a_message_are_refused_not_written_as_text() -> None:
    """Only a message's top-level bytes are written (as base64); bytes deeper down are refused,
    whichever way the message's JSON is written."""

    class Inner(BaseModel):
        blob: bytes

    class Outer(BaseModel):
        inner: Inner

    with pytest.raises(TypeError):
        to_json(Outer(inner=Inner(blob=b"ab")))
