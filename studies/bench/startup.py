"""Each component's start-up: from the process's start to its liveliness token, and its imports.

Run as ``python -m studies.bench.startup [--runs N] [--json]``. Every component of
deploy/emulated.yaml, and the staging supervisor, is started on its own (as the launcher
starts it, ``python -m components.<module> --profile P --name N``) against a router of the
bench's, ``--runs`` times each: ``alive_ms`` is the time until the router sees its
liveliness token, ``import_ms`` the time ``python -c "import components.<module>"`` takes.
A driver that dies comes back in about ``alive_ms`` after the launcher notices (every 50 ms):
that is most of the time its robot goes on with its last command.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import yaml
import zenoh

from messages import process, topics
from outputs.stdout import result_only_stdout, table
from profiles.deploy_files import DEPLOY
from profiles.endpoints import free_port
from profiles.profile import load_profile
from profiles.profile_files import read_profile_data
from studies.bench.figures import run_bench, spread


def bench_profile(directory: Path) -> Path:
    """deploy/emulated.yaml with the supervisor, its links and router in ``directory``."""
    data = read_profile_data(DEPLOY / "emulated.yaml")
    data["namespace"] = "startup"
    data["zenoh"]["router"] = [f"tcp/127.0.0.1:{free_port()}"]
    for spec in data["components"]:
        if spec["name"] == "simulator":
            spec["params"].update(
                create_link=str(directory / "create2"), servo_link=str(directory / "servos")
            )
    data["components"].append({"name": "supervisor", "module": "supervisor", "role": "controller"})
    path = directory / "startup.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


class Tokens:
    """When each component's liveliness token appeared."""

    def __init__(self, session: zenoh.Session, namespace: str) -> None:
        self.namespace = namespace
        self.seen: dict[str, int] = {}
        self.changed = threading.Condition()
        self._subscriber = session.liveliness().declare_subscriber(
            topics.liveliness_selector(namespace), self._on_sample
        )

    def _on_sample(self, sample: zenoh.Sample) -> None:
        if sample.kind != zenoh.SampleKind.PUT:
            return
        name = topics.component_of_liveliness_key(self.namespace, str(sample.key_expr))
        with self.changed:
            self.seen[name] = time.monotonic_ns()
            self.changed.notify_all()

    def wait(self, name: str, after_ns: int, timeout_s: float = 60.0) -> int:
        with self.changed:
            if not self.changed.wait_for(lambda: self.seen.get(name, 0) > after_ns, timeout_s):
                raise RuntimeError(f"{name} not alive within {timeout_s} s")
            return self.seen[name]


def alive_ms(path: Path, module: str, name: str, tokens: Tokens) -> float:
    started = time.monotonic_ns()
    child = subprocess.Popen(
        process.command(module, path, name), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    try:
        return (tokens.wait(name, started) - started) / 1e6
    finally:
        child.terminate()
        child.wait(30)


def import_ms(module: str) -> float:
    started = time.monotonic_ns()
    subprocess.run([sys.executable, "-c", f"import {module}"], check=True)
    return (time.monotonic_ns() - started) / 1e6


def measure(runs: int) -> dict:
    with tempfile.TemporaryDirectory(prefix="parsimony-startup-") as directory:
        path = bench_profile(Path(directory))
        profile = load_profile(path)
        results = {}
        with zenoh.open(profile.zenoh.router_config(profile.namespace)) as router:
            tokens = Tokens(router, profile.namespace)
            for spec in profile.components:
                if not spec.enabled:
                    continue
                alive = [alive_ms(path, spec.module_path, spec.name, tokens) for _ in range(runs)]
                imports = [import_ms(spec.module_path) for _ in range(runs)]
                results[spec.name] = {
                    "module": spec.module_path,
                    "alive_ms": spread(alive),
                    "import_ms": spread(imports),
                }
    return {"bench": "startup", "components": results}


def lines(report: dict) -> list[str]:
    rows = [
        {
            "component": name,
            "alive_ms_median": f["alive_ms"]["median"],
            "alive_ms_max": f["alive_ms"]["max"],
            "import_ms_median": f["import_ms"]["median"],
            "import_ms_max": f["import_ms"]["max"],
        }
        for name, f in report["components"].items()
    ]
    return [table(rows)]


def main(argv: list[str] | None = None) -> int:
    return run_bench(__doc__, measure, lines, 5, argv)


if __name__ == "__main__":
    with result_only_stdout():
        code = main()
    sys.exit(code)
