"""The launcher's output: each line whole, stamped with the local time and prefixed with who
said it; its own lines on the error stream; a child's pipe copied line by line."""

from __future__ import annotations

import io
import re
import threading

from launch.output import Output

LINE = re.compile(r"\d\d:\d\d:\d\d\.\d{3} \[(?P<prefix>[^]]+)\] (?P<text>.*)")


class Chunked(io.StringIO):
    """A stream that takes each write in two pieces, as a pipe may: lines written by threads
    without a lock between them would interleave."""

    def write(self, text: str) -> int:
        half = len(text) // 2
        super().write(text[:half])
        threading.Event().wait(0)  # let another thread in between the pieces
        return super().write(text[half:])


def parsed(stream: io.StringIO) -> list[tuple[str, str]]:
    lines = stream.getvalue().splitlines()
    matches = [LINE.fullmatch(line) for line in lines]
    assert all(matches), lines
    return [(m["prefix"], m["text"]) for m in matches]


def test_a_line_is_stamped_and_prefixed_its_trailing_space_dropped() -> None:
    out, err = io.StringIO(), io.StringIO()
    Output(out, err).line(out, "controller", "ready  \n")
    assert parsed(out) == [("controller", "ready")]
    assert out.getvalue().endswith("ready\n") and err.getvalue() == ""


def test_the_launchers_own_lines_go_to_the_error_stream() -> None:
    out, err = io.StringIO(), io.StringIO()
    Output(out, err).say("router on tcp/127.0.0.1:7448")
    assert out.getvalue() == ""
    assert parsed(err) == [("launch", "router on tcp/127.0.0.1:7448")]


def test_a_childs_pipe_is_copied_line_by_line_and_closed() -> None:
    out, err = io.StringIO(), io.StringIO()
    pipe = io.StringIO("first\nsecond\r\nlast without newline")
    Output(out, err).forward(pipe, out, "simulator")
    assert parsed(out) == [
        ("simulator", "first"),
        ("simulator", "second"),
        ("simulator", "last without newline"),
    ]
    assert pipe.closed


def test_lines_from_many_threads_stay_whole() -> None:
    out = Chunked()
    output = Output(out, out)
    writers = [
        threading.Thread(
            target=lambda n=n: [
                output.line(out, f"child{n}", f"line {i} of {n}") for i in range(50)
            ]
        )
        for n in range(4)
    ]
    for writer in writers:
        writer.start()
    for writer in writers:
        writer.join()
    lines = parsed(out)
    assert len(lines) == 200
    for n in range(4):
        mine = [text for prefix, text in lines if prefix == f"child{n}"]
        assert mine == [f"line {i} of {n}" for i in range(50)]
