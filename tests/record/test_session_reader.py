"""record.session_reader on real MCAP files: what info counts, files cut short as a recorder
killed by SIGKILL leaves them and their recovery, chunks out of order, only the topics asked
for, and the same memory whatever the length."""

from __future__ import annotations

import random
import tracemalloc
from pathlib import Path

import pytest
from mcap.exceptions import McapError
from mcap.reader import make_reader

from messages import topics
from messages.clock import Clock
from record.session_file import SessionWriter
from record.session_reader import info, read_session, recover
from tests.record.session_messages import (
    NAMESPACE,
    image,
    state,
    states_in,
    write_flushed,
)


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
