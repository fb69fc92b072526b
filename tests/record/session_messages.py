"""Messages to record and a session file written in flushed chunks, shared by the tests of
record.session_file and record.session_reader."""

from __future__ import annotations

import random
from pathlib import Path

from messages import topics
from messages.camera import CameraFrame
from messages.header import Header
from messages.state import RobotState
from record.session_file import SessionWriter
from record.session_reader import read_session

NAMESPACE = "lab/robot1"


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
