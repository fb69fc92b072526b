"""The recorder a profile adds to record a system: ``parsimony record``, ``launch --record`` and
the experiments extend a profile with it (``components.recorder`` is the component itself)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import yaml

RECORDER = "recorder"
"""The name of the recorder component that ``record``, ``launch --record`` and ``experiment``
add."""
RECORDER_STOP_S = 10.0
"""Host seconds a stopping recorder may go without progress before it is killed; it stops
after everything else and writes all that still waits for it, however long that takes."""


def recorder_component(output: Path, keys: Sequence[str] = ("*",)) -> dict[str, object]:
    """A profile's recorder writing every topic matching one of ``keys`` to ``output``: role
    ``recorder`` (it starts first and stops last, writing all that still waits), never
    restarted (a new one would begin the file again; a killed one's file recovers)."""
    return {
        "name": RECORDER,
        "module": "recorder",
        "role": "recorder",
        "enabled": True,
        "stop_timeout_s": RECORDER_STOP_S,
        "restart": {"policy": "never"},
        "params": {"path": str(Path(output).resolve()), "keys": ",".join(keys)},
    }


def with_recorder(profile: Path, output: Path, keys: Sequence[str] = ("*",)) -> str:
    """The YAML text of a profile that extends ``profile`` with ``recorder_component``."""
    components = [recorder_component(output, keys)]
    return yaml.safe_dump({"extends": str(Path(profile).resolve()), "components": components})
