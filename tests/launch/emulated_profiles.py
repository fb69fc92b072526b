"""An emulated profile of deploy/ for one test: a free router port, the emulated devices'
pseudo-terminals in the test's own directory."""

from __future__ import annotations

from pathlib import Path

import yaml

from profiles.deploy_files import DEPLOY
from profiles.endpoints import free_port


def emulated_profile(
    tmp_path: Path, namespace: str, *components: dict, base: str = "emulated.yaml"
) -> Path:
    """deploy/``base`` (an emulated profile) on a free port, its devices in ``tmp_path``."""
    data = {
        "extends": str(DEPLOY / base),
        "namespace": namespace,
        "zenoh": {"router": [f"tcp/127.0.0.1:{free_port()}"]},
        "components": [
            {
                "name": "simulator",
                "params": {
                    "create_link": str(tmp_path / "create2"),
                    "servo_link": str(tmp_path / "servos"),
                },
            },
            {"name": "base_driver", "params": {"port": str(tmp_path / "create2")}},
            {"name": "arm_driver", "params": {"port": str(tmp_path / "servos")}},
            *components,
        ],
    }
    path = tmp_path / "profile.yaml"
    path.write_text(yaml.safe_dump(data))
    return path
