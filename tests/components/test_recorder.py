"""The recorder process on simulated time. The launcher starts it first, before the simulator
whose clock it follows: it waits for the clock's first tick, and calls the clock stalled only
once it has stopped (before, ``launch --record`` said ``recorder running (was clock stalled)``
at every start, and the recorder counted a stall that ``parsimony status`` showed as a fault)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING

import yaml
import zenoh

from components.recorder import Recorder
from components.runtime import Node
from launch import query
from messages import codec, topics
from messages.clock import Clock
from messages.header import Header
from profiles.endpoints import free_port
from profiles.profile import load_profile
from profiles.recorder import recorder_component
from record.session_reader import info
from tests.components.conftest import System
from tests.components.plain_state import robot_state

if TYPE_CHECKING:
    from tests.components.conftest import WaitUntil

NAMESPACE = "rec"


def test_the_recorder_waits_for_the_clocks_first_tick_and_says_a_stall_only_after_it(
    tmp_path: Path, wait_until: WaitUntil
) -> None:
    path = tmp_path / "rec.yaml"
    path.write_text(
        yaml.safe_dump(
            {
                "namespace": NAMESPACE,
                "clock": "sim",
                "clock_timeout_s": 0.2,
                "zenoh": {"router": [f"tcp/127.0.0.1:{free_port()}"]},
                "components": [recorder_component(tmp_path / "k.mcap")],
            }
        )
    )
    profile = load_profile(path)
    with zenoh.open(profile.zenoh.router_config()) as router:
        system = System(path, profile, router)
        try:
            liveliness = system.liveliness()
            system.start("recorder")
            liveliness.wait_for("recorder", alive=True)
            # Its clock was made before it was alive: a clock that has not started would be
            # stalled by now. Each query is answered on its handler thread, which checks the
            # clock after each: the second answer tells what the check after the first found.
            time.sleep(profile.clock_timeout_s)
            query.statuses(router, NAMESPACE)
            waiting = query.statuses(router, NAMESPACE)["recorder"]
            assert waiting.state == "waiting for the clock"
            assert waiting.counters["clock_stalls"] == 0
            assert "sim/clock has not moved" not in system.log("recorder")

            clock = router.declare_publisher(topics.SIM_CLOCK.key(NAMESPACE))
            stamps = iter(range(10_000_000, 10**12, 10_000_000))

            def ticked_and_running() -> bool:
                clock.put(codec.encode(Clock(stamp_ns=next(stamps))))
                return query.statuses(router, NAMESPACE)["recorder"].state == "running"

            wait_until(ticked_and_running, "the recorder to run on the clock")
            wait_until(
                lambda: query.statuses(router, NAMESPACE)["recorder"].state == "clock stalled",
                "the stopped clock to be called stalled",
            )
            stalled = query.statuses(router, NAMESPACE)["recorder"]
            assert stalled.counters["clock_stalls"] == 1
        finally:
            system.stop_processes()


def test_a_message_lost_on_its_way_to_the_recorder_is_counted_by_its_publishers_seq_gap(
    system: System, tmp_path: Path, wait_until: WaitUntil
) -> None:
    """States of two sources, one skipping seq 3 and 4 (as Zenoh's drop of a full queue leaves
    them), then started anew at 0 (a restarted component: no loss): the file says 2 missed."""
    path = tmp_path / "gaps.mcap"
    sent = [("a", 0), ("a", 1), ("a", 2), ("b", 0), ("a", 5), ("b", 1), ("a", 0), ("a", 1)]
    with Node(system.profile, "listener", Recorder.params, Recorder.reads, ()) as node:
        node.params.set("path", str(path))
        node.params.set("views", False)
        recorder = Recorder(node)
        node.start(recorder.shutdown)
        states = system.router.declare_publisher(
            topics.ROBOT_STATE.key(system.profile.namespace),
            congestion_control=zenoh.CongestionControl.BLOCK,
        )
        wait_until(lambda: states.matching_status.matching, "the recorder to subscribe")
        for source, seq in sent:
            header = Header(stamp_ns=time.time_ns(), frame="world", seq=seq, source=source)
            states.put(codec.encode(robot_state().model_copy(update={"header": header})))
        wait_until(lambda: node.counters["written"] == len(sent), "every state written")
    assert info(path)["dropped"] == {"missed.robot/state": 2}
