"""The profile's clock as a tool reads it (launch/tool_clock.py): the host's on a wall-clock
profile, the simulator's latest sim/clock on a sim one, and a clear error when none comes."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
import yaml
import zenoh

from launch.tool_clock import NoClock, ToolClock
from messages import codec, topics
from messages.clock import Clock
from profiles.endpoints import free_port
from profiles.profile import Profile, load_profile


def profile(tmp_path: Path, clock: str) -> Profile:
    path = tmp_path / f"{clock}.yaml"
    pub = {"name": "pub", "module": "scripted_publisher", "role": "tool"}
    router = {"router": [f"tcp/127.0.0.1:{free_port()}"]}
    data = {"namespace": "clock", "clock": clock, "zenoh": router, "components": [pub]}
    path.write_text(yaml.safe_dump(data))
    return load_profile(path)


def test_a_sim_profile_stamps_with_the_simulators_clock_and_says_when_there_is_none(
    tmp_path: Path,
) -> None:
    sim = profile(tmp_path, "sim")
    with zenoh.open(sim.zenoh.router_config()) as session, ToolClock(session, sim) as clock:
        assert clock.now_ns() is None
        with pytest.raises(NoClock, match="no simulator clock on clock/sim/clock in 0.1 s"):
            clock.wait_ns(0.1)
        session.put(topics.SIM_CLOCK.key("clock"), codec.encode(Clock(stamp_ns=42_000)))
        header = clock.header(seq=3, source="tool", timeout_s=30.0)
    assert (header.stamp_ns, header.seq, header.source) == (42_000, 3, "tool")


def test_a_wall_profile_stamps_with_the_hosts_time(tmp_path: Path) -> None:
    wall = profile(tmp_path, "wall")
    with zenoh.open(wall.zenoh.router_config()) as session, ToolClock(session, wall) as clock:
        before = time.time_ns()
        assert before <= clock.wait_ns(0.0) <= time.time_ns()
