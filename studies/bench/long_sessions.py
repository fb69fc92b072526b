"""Long sessions for the recording benchmark: a recording repeated copy after copy to span
any length, and the peak memory of the commands that read a whole file on them."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

from pydantic import BaseModel

from record.session_file import SessionWriter, stamp_of
from record.session_reader import read_session

REPEAT_GAP_NS = 10_000_000
"""Between the last stamp of one copy of a session and the first of the next (a 100 Hz step)."""

MEMORY_REPLAY_RATE = 64.0
"""The rate of the replays whose memory is measured (their timing is part 2's)."""


def shifted(recorded: BaseModel, offset_ns: int) -> BaseModel:
    """The message with its stamp (its header's, or a clock's) ``offset_ns`` later."""
    header = getattr(recorded, "header", None)
    if header is None:
        return recorded.model_copy(update={"stamp_ns": recorded.stamp_ns + offset_ns})
    later = header.model_copy(update={"stamp_ns": header.stamp_ns + offset_ns})
    return recorded.model_copy(update={"header": later})


def repeated_session(source: Path, target: Path, seconds: float) -> float:
    """Write at ``target`` the project messages of ``source`` and their Foxglove views (as the
    recorder writes them), copy after copy, each copy's stamps shifted to follow the last,
    until ``seconds`` from the first stamp; return the seconds it spans."""
    records = [r for r in read_session(source) if r.message is not None]
    first, last = records[0].log_time_ns, records[-1].log_time_ns
    period, end = last - first + REPEAT_GAP_NS, first + round(seconds * 1e9)
    latest, copy = first, 0
    with SessionWriter(target) as writer:
        while first + copy * period <= end:
            for r in records:
                if r.log_time_ns + copy * period > end:
                    break
                repeated = shifted(r.message, copy * period)
                writer.write(r.key, repeated, views=True)
                latest = stamp_of(repeated)
            copy += 1
    return (latest - first) / 1e9


PEAK_MEMORY = """\
import os, sys
pid = os.fork()
if pid == 0:
    os.execv(sys.executable, [sys.executable, *sys.argv[2:]])
_, status, usage = os.wait4(pid, 0)
with open(sys.argv[1], "w") as out:
    out.write(str(usage.ru_maxrss))
sys.exit(os.waitstatus_to_exitcode(status))
"""
"""A small parent that runs a command and writes its peak resident memory (KiB): a process's
``ru_maxrss`` counts the one it was forked from, so this bench's own memory would count in a
child it forked itself."""


def peak_memory_mb(arguments: Sequence[str], directory: Path) -> float:
    """``parsimony ARGUMENTS`` as a process: its peak resident memory, MB (it must exit 0)."""
    peak = directory / "peak_kib"
    command = [sys.executable, "-c", PEAK_MEMORY, str(peak), "-m", "parsimony.cli", *arguments]
    done = subprocess.run(command, stdout=subprocess.DEVNULL)
    if done.returncode != 0:
        raise RuntimeError(f"parsimony {' '.join(arguments)} failed (exit {done.returncode})")
    return round(int(peak.read_text()) / 1024, 1)


def memory_use(
    recorded: Path, spans_s: Sequence[float], profile: Path, directory: Path
) -> list[dict]:
    """Peak memory of the commands that read a whole file, on the recording repeated to span
    each of ``spans_s``; then each command's ratio of the longest span's to the shortest's."""
    rows = []
    for span in spans_s:
        session = directory / f"span{span:g}.mcap"
        print(f"[bench] memory: a {span:g} s session", file=sys.stderr, flush=True)
        repeated_session(recorded, session, span)
        out = directory / f"memory{span:g}"
        commands = {
            "info": ["info", str(session)],
            "report": ["report", str(session), "--out", str(out)],
            "rerun": ["rerun", str(session), "--controller", "lp", "-o", str(out / "rerun.mcap")],
            "replay": [
                "replay",
                str(session),
                "--profile",
                str(profile),
                "--rate",
                f"{MEMORY_REPLAY_RATE:g}",
            ],
        }
        row = {"session_s": span, "file_MB": round(session.stat().st_size / 1e6, 1)}
        row |= {
            f"{name}_MB": peak_memory_mb(arguments, directory)
            for name, arguments in commands.items()
        }
        rows.append(row)
        session.unlink()
    first, last = rows[0], rows[-1]
    rows.append(
        {
            "session_s": "ratio",
            **{k: round(last[k] / first[k], 2) for k in first if k.endswith("_MB")},
        }
    )
    return rows
