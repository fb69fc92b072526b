"""Broken and foreign files through the real commands: one line naming the file and exit 2,
never a traceback; a damaged chunk skipped and named, and every other message read. (Each
command by its entry point in the test's process, tests/parsimony/in_process.py, but where
what it says comes from the log, which a process of its own prints on stderr.)"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest
from mcap.reader import make_reader

from messages import topics
from messages.header import Header
from messages.state import RobotState
from profiles.endpoints import free_port
from record.session_file import SessionWriter, entries
from record.session_reader import info, read_session, recover
from tests.parsimony.in_process import run_in_process
from tests.processes import parsimony

KEY = topics.ROBOT_STATE.key("bad")
MESSAGES = 3000


def state(index: int) -> RobotState:
    return RobotState(
        header=Header(stamp_ns=index * 20_000_000, frame="world", seq=index, source="test"),
        base_pose=(index * 1e-3, 2.0, 0.3),
        arm_joints=(0.1, -0.2, 0.3, -0.4, 0.5),
        end_effector=(1.0, 0, 0, 0, 0, 0, 0, 0),
        valid=True,
        age_s=0.0,
    )


@pytest.fixture
def session(tmp_path: Path) -> Path:
    """A whole session of many small chunks."""
    path = tmp_path / "good.mcap"
    with SessionWriter(path, chunk_size=16_000) as writer:
        for index in range(MESSAGES):
            writer.write(KEY, state(index))
    return path


def damaged(session: Path, tmp_path: Path) -> tuple[Path, int]:
    """The session with 100 bytes flipped inside its fourth chunk; the messages that chunk held."""
    with session.open("rb") as stream:
        chunk = make_reader(stream).get_summary().chunk_indexes[3]
    data = bytearray(session.read_bytes())
    middle = chunk.chunk_start_offset + chunk.chunk_length // 2
    for offset in range(middle, middle + 100):
        data[offset] ^= 0xFF
    path = tmp_path / "flipped.mcap"
    path.write_bytes(bytes(data))
    with session.open("rb") as stream:
        held = sum(
            1
            for _, _, m in make_reader(stream).iter_messages()
            if chunk.message_start_time <= m.log_time <= chunk.message_end_time
        )
    return path, held


FOREIGN = {"text": b"this is not a recording\n" * 20, "zeros": bytes(4096), "short": b"\x89MCAX"}


@pytest.mark.parametrize("kind", sorted(FOREIGN))
def test_a_file_that_is_not_mcap_is_said_in_one_line_by_every_command(
    tmp_path: Path, kind: str, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / f"{kind}.mcap"
    path.write_bytes(FOREIGN[kind])
    out = str(tmp_path / "out.mcap")
    every = (
        ["info", str(path)],
        ["report", str(path), "--out", str(tmp_path / "r")],
        ["rerun", str(path), "--controller", "lp", "-o", out],
        ["record", "--recover", str(path), "-o", out],
    )
    for arguments in every if kind == "text" else every[:1]:  # all read through one scan
        code, _, err = run_in_process(arguments, capsys)
        assert code == 2, (arguments, err)
        assert "Traceback" not in err, err
        assert f"{path}: not an MCAP file" in err, (arguments, err)


def test_a_damaged_chunk_is_skipped_named_and_the_rest_read(
    session: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, held = damaged(session, tmp_path)
    found = info(path)
    assert len(found["damaged"]) == 1 and found["complete"]
    assert found["messages"] == MESSAGES - held and 0 < held < MESSAGES / 10
    states = [r.message for r in read_session(path)]
    assert len(states) == MESSAGES - held
    assert all(s == state(s.header.seq) for s in states)  # every other message, exactly
    # `info` says so; `record --recover` keeps every message of the other chunks.
    code, out, err = run_in_process(["info", str(path)], capsys)
    assert code == 0 and "damaged, skipped: the chunk of" in out
    assert "Traceback" not in err
    whole = tmp_path / "whole.mcap"
    done = parsimony("record", "--recover", str(path), "-o", str(whole))
    assert done.returncode == 0 and "skipped the chunk of" in done.stderr, done.stderr
    assert info(whole)["messages"] == MESSAGES - held and info(whole)["damaged"] == []
    assert recover(path, tmp_path / "again.mcap") == MESSAGES - held


def test_messages_that_do_not_decode_are_skipped_and_said_with_channel_and_time(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    path = tmp_path / "wrong.mcap"
    with SessionWriter(path) as writer:
        for index in range(10):
            writer.write(KEY, state(index))
        (entry,) = entries(KEY, state(10), views=False)
        for data in (b"{not json", b'{"header": 3}'):
            writer.write_raw(dataclasses.replace(entry, data=data), 11 * 20_000_000)
    recorded = list(read_session(path))
    assert [r.message.header.seq for r in recorded] == list(range(10))
    said = caplog.text
    assert f"skipped the message of {KEY} at 0.220 s: not a RobotState" in said, said
    assert f"skipped 2 messages of {KEY} in all" in said
    done = parsimony("report", str(path), "--out", str(tmp_path / "r"))
    assert "Traceback" not in done.stderr and f"skipped the message of {KEY}" in done.stderr


BAD_ARGUMENTS = {
    "--rate 0": (["--rate", "0"], "--rate: expected a finite number of times the recorded"),
    "--start-offset past the end": (["--start-offset", "1000"], "nothing in the window"),
    "--start-offset nan": (["--start-offset", "nan"], "--start-offset: expected seconds >= 0"),
    "--keys matching nothing": (
        ["--keys", "robot/state", "robot/stat"],
        "'robot/stat' matches no topic",
    ),
    "--keys none in the file": (["--keys", "camera/*"], "nothing to replay"),
    "--namespace *": (["--namespace", "*"], "must not contain the wildcard"),
    "--namespace ''": (["--namespace", ""], "namespace must not be empty"),
}


@pytest.mark.parametrize("case", sorted(BAD_ARGUMENTS))
def test_bad_replay_arguments_are_said_before_any_router_is_reached(
    session: Path, tmp_path: Path, case: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """Each is refused, said on the last line, exit 2; the profile's router is not there, so a
    check made after connecting would say that instead."""
    profile = tmp_path / "p.yaml"
    profile.write_text(
        f"namespace: bad\nzenoh: {{router: ['tcp/127.0.0.1:{free_port()}']}}\n"
        "components: [{name: pub, module: scripted_publisher, role: tool}]\n"
    )
    arguments, said = BAD_ARGUMENTS[case]
    code, _, err = run_in_process(
        ["replay", str(session), "--profile", str(profile), *arguments], capsys
    )
    assert code == 2, err
    assert said in err.strip().splitlines()[-1], err
    assert "router" not in err and "Traceback" not in err, err


@pytest.mark.parametrize("keys", [[], ["robot/state", "robots/*"]])
def test_record_refuses_keys_that_match_no_topic(
    tmp_path: Path, keys: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    profile = tmp_path / "p.yaml"
    profile.write_text(
        "namespace: bad\ncomponents: [{name: pub, module: scripted_publisher, role: tool}]\n"
    )
    argv = ["record", str(profile), "-o", str(tmp_path / "k.mcap"), "--keys", *keys]
    code, _, err = run_in_process(argv, capsys)
    assert code == 2 and "keys: " in err, err
    assert not (tmp_path / "k.mcap").exists()


def foxglove_file(path: Path) -> Path:
    """An MCAP file written by foxglove-sdk, as another tool would: a pose on a channel of
    Foxglove's schema, and JSON on a key that ends like one of ours but is not our type."""
    import foxglove
    from foxglove.channels import PoseInFrameChannel
    from foxglove.messages import Pose, PoseInFrame, Quaternion, Timestamp, Vector3

    context = foxglove.Context()
    with foxglove.open_mcap(path, context=context):
        poses = PoseInFrameChannel("/goal", context=context)
        state = foxglove.Channel(
            "other/robot/state", schema={"type": "object"}, message_encoding="json", context=context
        )
        for index in range(50):
            stamp = Timestamp(sec=index, nsec=0)
            poses.log(
                PoseInFrame(
                    timestamp=stamp,
                    frame_id="world",
                    pose=Pose(
                        position=Vector3(x=index, y=0, z=0),
                        orientation=Quaternion(x=0, y=0, z=0, w=1),
                    ),
                ),
                log_time=index * 10**9,
            )
            state.log({"x": index}, log_time=index * 10**9)
    return path


def test_a_file_of_another_tool_is_read_for_what_it_holds(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`info` lists its channels, none of them ours; `report` and `replay` say it holds nothing
    of ours (exit 2); `record --recover` keeps every message."""
    path = foxglove_file(tmp_path / "foxglove.mcap")
    shown = info(path)
    assert shown["complete"] and shown["messages"] == 100
    assert {c["key"]: c["topic"] for c in shown["channels"]} == {
        "/goal": None,
        "other/robot/state": None,
    }
    assert {r.topic_name for r in read_session(path)} == {None}
    code, _, err = run_in_process(["report", str(path), "--out", str(tmp_path / "r")], capsys)
    assert code == 2 and "the session has no messages on topic" in err
    profile = tmp_path / "p.yaml"
    profile.write_text(
        "namespace: bad\ncomponents: [{name: pub, module: scripted_publisher, role: tool}]\n"
    )
    code, _, err = run_in_process(["replay", str(path), "--profile", str(profile)], capsys)
    assert code == 2 and "nothing to replay" in err, err
    assert recover(path, tmp_path / "copy.mcap") == 100
    assert info(tmp_path / "copy.mcap")["channels"] == shown["channels"]
