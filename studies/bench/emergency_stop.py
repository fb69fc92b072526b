"""The latched emergency stop's figures, on the emulated Create 2 and AX-18A chain, through
``parsimony launch`` (the drivers of deploy/hardware.yaml, as ``studies.bench.driver_safety``).

Run as ``python -m studies.bench.emergency_stop [--runs N] [--json]``. The bench plays a
controller that goes on sending motion at 50 Hz (one control period: 20 ms) whatever happens,
drives the wheels at 0.1 m/s and the first joint at 0.4 rad/s, and puts a stop on
``control/stop`` as ``parsimony stop`` does (host monotonic times, the emulators' own):

- ``stop_to_wheels_zero_ms``: from the stop to the zero Drive Direct on the Create's line;
- ``stop_to_last_motion_ms``: from the stop to the last non-zero Drive Direct (0 when none
  came after it);
- ``stop_to_arm_hold_ms``: from the stop to the first Sync Write on the servos' line after it
  (the hold: every goal where its joint is read, at the slow hold speed; within 1 ms, the
  bench polls the emulator's count);
- ``stop_to_arm_still_ms``: from the stop to every servo at rest (a joint read while it moved
  goes back to where it was read at the hold speed);
- ``moved_while_stopped``: non-zero Drive Directs and joint motions after those, until the
  release, the controller still sending (and once per run the base driver killed with
  ``kill -9`` and started again by the launcher: it starts stopped); it must be 0;
- ``release_to_motion_ms``: from the release to the first non-zero Drive Direct.
"""

from __future__ import annotations

import os
import signal
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

from components.stop_latch import stop_state
from messages import codec, topics
from outputs.stdout import result_only_stdout, table
from studies.bench.driver_safety import Rig, wait
from studies.bench.figures import run_bench, spread

CONTROL_PERIOD_MS = 20.0
"""The bench controller's period (the profile's controller runs at 50 Hz too)."""
STOPPED_S = 0.5
"""How long each run holds the stop, the controller sending, before the release."""


class MotionLog:
    """When the servos last moved, noted by the emulated chain's calls (host monotonic ns)."""

    def __init__(self, rig: Rig) -> None:
        self.moved_ns = 0
        told = rig.joints.set_joint_velocities

        def noted(velocities: Sequence[float]) -> None:
            if any(velocities):
                self.moved_ns = time.monotonic_ns()
            told(velocities)

        rig.joints.set_joint_velocities = noted  # type: ignore[method-assign]


def give(rig: Rig, stopped: bool) -> int:
    """Put a stop (or a release) now; its host monotonic time."""
    at = time.monotonic_ns()
    state = stop_state(stopped, "bench", "emergency stop bench")
    rig.session.put(topics.CONTROL_STOP.key(rig.profile.namespace), codec.encode(state))
    return at


def moving_after(rig: Rig, since_ns: int) -> list[int]:
    """When the wheels were told a non-zero speed after ``since_ns``."""
    with rig.wheels.lock:
        return [t for t, left, right in rig.wheels.told if t > since_ns and (left or right)]


def one_stop(rig: Rig, motion: MotionLog, run: int, kill: bool) -> dict[str, float]:
    """Drive, stop, hold the stop (killing the base driver when ``kill``), release."""
    direction = 1.0 if run % 2 == 0 else -1.0
    rig.controller.speed = 0.1
    rig.controller.joints = (0.4 * direction, 0.0, 0.0, 0.0, 0.0)
    driving = time.monotonic_ns()
    wait(lambda: moving_after(rig, driving) and motion.moved_ns > driving, "the robot moving")
    writes = rig.servos.counters["sync_writes"]
    stopped = give(rig, True)
    held = wait(
        lambda: rig.servos.counters["sync_writes"] > writes and time.monotonic_ns(), "the hold"
    )
    zero = wait(lambda: rig.wheels.stopped_after(stopped), "the wheels stopped")
    still = wait(lambda: rig.joints.still_since_ns, "the arm at rest")
    if kill:
        pid = wait(lambda: rig.pid("base_driver"), "the base driver's pid")
        os.kill(pid, signal.SIGKILL)
        wait(lambda old=pid: rig.pid("base_driver") not in (None, old), "the base driver back")
    time.sleep(STOPPED_S)  # the controller still sending, 25 control periods
    released = give(rig, False)
    late = moving_after(rig, stopped)
    moved = [t for t in late if zero < t < released] + (
        [motion.moved_ns] if still < motion.moved_ns < released else []
    )
    back = wait(lambda: moving_after(rig, released), "the wheels driven again")[0]
    rig.controller.speed = rig.controller.joints = None
    return {
        "zero": (zero - stopped) / 1e6,
        "last": max(0, max((t for t in late if t < zero), default=stopped) - stopped) / 1e6,
        "held": (held - stopped) / 1e6,
        "still": max(0, still - stopped) / 1e6,
        "moved": len(moved),
        "back": (back - released) / 1e6,
    }


def measure(runs: int) -> dict:
    with (
        tempfile.TemporaryDirectory(prefix="parsimony-stop-") as directory,
        Rig(Path(directory)) as rig,
    ):
        motion = MotionLog(rig)
        results = [one_stop(rig, motion, run, kill=run == 0) for run in range(runs)]
    return {
        "bench": "emergency_stop",
        "stop_to_wheels_zero_ms": spread([r["zero"] for r in results]),
        "stop_to_last_motion_ms": spread([r["last"] for r in results]),
        "stop_to_arm_hold_ms": spread([r["held"] for r in results]),
        "stop_to_arm_still_ms": spread([r["still"] for r in results]),
        "release_to_motion_ms": spread([r["back"] for r in results]),
        "moved_while_stopped": sum(r["moved"] for r in results),
        "control_period_ms": CONTROL_PERIOD_MS,
    }


def lines(report: dict) -> list[str]:
    rows = [{"figure": name, **value} for name, value in report.items() if isinstance(value, dict)]
    counts = f"moved while stopped: {report['moved_while_stopped']} (must be 0)"
    return [table(rows), counts, f"control period: {report['control_period_ms']} ms"]


def main(argv: list[str] | None = None) -> int:
    return run_bench(__doc__, measure, lines, 10, argv)


if __name__ == "__main__":
    with result_only_stdout():
        code = main()
    sys.exit(code)
