"""Each component's start-up: from the process's start to its liveliness token; and the CPU a
process spends before its work, component or command.

Run as ``python -m studies.bench.startup [--runs N] [--json] [--only WORD]``. Every component of
deploy/emulated.yaml, and the staging supervisor, is started on its own (as the launcher
starts it, ``python -m components.<module> --profile P --name N``) against a router of the
bench's, ``--runs`` times each: ``alive_ms`` is the time until the router sees its
liveliness token, ``cpu_ms`` the CPU time it spent (imports, profile, robot, session, token;
and its stop on SIGTERM right after). Then each process start (every component module's import,
``python -c "import components.<module>"``, and the commands the tests run most,
``python -m parsimony.cli <command> --help``, which imports that command's module alone, and
``parsimony --help``, which imports them all) runs ``--runs`` times, the starts interleaved:
``wall_ms`` from its start to its end, ``cpu_ms`` its user and system time. ``--only WORD``
keeps the components and starts whose name holds WORD.
A driver that dies comes back in about ``alive_ms`` after the launcher notices (every 50 ms):
that is most of the time its robot goes on with its last command.
"""

from __future__ import annotations

import argparse
import resource
import signal
import subprocess
import sys
import tempfile
import threading
import time
from functools import partial
from pathlib import Path

import yaml
import zenoh

import components
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


def children_cpu_ms() -> float:
    """The user and system time of every child process of the bench's that has ended, ms."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (usage.ru_utime + usage.ru_stime) * 1e3


def alive_cost(path: Path, module: str, name: str, tokens: Tokens) -> tuple[float, float]:
    """The component's ``alive_ms``, and its CPU time from its start to its end on SIGTERM
    right after its token (ms)."""
    cpu_before = children_cpu_ms()
    started = time.monotonic_ns()
    child = subprocess.Popen(
        process.command(module, path, name), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    try:
        alive = (tokens.wait(name, started) - started) / 1e6
    finally:
        process.stop(child, signal.SIGTERM, 30.0)  # then killed: a loaded machine is slow
    return alive, children_cpu_ms() - cpu_before


COMMANDS = ("experiment", "launch", "status", "record", "replay", "view", "goal")
"""The commands the tests run most: the start of ``parsimony <command> --help`` (that command's
module alone) is measured, and that of ``parsimony --help`` (every command's)."""


def component_modules() -> list[str]:
    """Every module of ``components`` that runs as a process (it calls ``run_component``)."""
    folder = Path(components.__file__).parent
    return sorted(
        f"components.{path.stem}"
        for path in folder.glob("*.py")
        if "\n    run_component(" in path.read_text()
    )


def starts() -> dict[str, list[str]]:
    """Each process start measured, by name: its command line."""
    imports = {m: [sys.executable, "-c", f"import {m}"] for m in component_modules()}
    words = [("--help",), *((command, "--help") for command in COMMANDS)]
    helps = {
        " ".join(("parsimony", *w)): [sys.executable, "-m", "parsimony.cli", *w] for w in words
    }
    return imports | helps


def process_cost(command: list[str]) -> tuple[float, float]:
    """Wall and CPU (user + system) ms of ``command`` from its start to its end."""
    cpu_before = children_cpu_ms()
    started = time.monotonic_ns()
    subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    return (time.monotonic_ns() - started) / 1e6, children_cpu_ms() - cpu_before


def start_costs(runs: int, only: str) -> dict:
    """Each start's ``wall_ms`` and ``cpu_ms``, the starts interleaved run by run (a machine
    whose load changes weighs on all of them alike)."""
    chosen = {name: command for name, command in starts().items() if only in name}
    costs: dict[str, list[tuple[float, float]]] = {name: [] for name in chosen}
    for _ in range(runs):
        for name, command in chosen.items():
            costs[name].append(process_cost(command))
    return {
        name: {"wall_ms": spread([w for w, _ in c]), "cpu_ms": spread([u for _, u in c])}
        for name, c in costs.items()
    }


def alive_times(runs: int, only: str) -> dict:
    """Each component's ``alive_ms``, started ``runs`` times against the bench's router."""
    with tempfile.TemporaryDirectory(prefix="parsimony-startup-") as directory:
        path = bench_profile(Path(directory))
        profile = load_profile(path)
        chosen = [
            spec
            for spec in profile.components
            if spec.enabled and (only in spec.name or only in spec.module_path)
        ]
        if not chosen:
            return {}
        results = {}
        with zenoh.open(profile.zenoh.router_config(profile.namespace)) as router:
            tokens = Tokens(router, profile.namespace)
            for spec in chosen:
                costs = [alive_cost(path, spec.module_path, spec.name, tokens) for _ in range(runs)]
                results[spec.name] = {
                    "module": spec.module_path,
                    "alive_ms": spread([alive for alive, _ in costs]),
                    "cpu_ms": spread([cpu for _, cpu in costs]),
                }
    return results


def measure(runs: int, only: str = "") -> dict:
    return {
        "bench": "startup",
        "components": alive_times(runs, only),
        "starts": start_costs(runs, only),
    }


def lines(report: dict) -> list[str]:
    alive = [
        {
            "component": name,
            "alive_ms_median": f["alive_ms"]["median"],
            "alive_ms_max": f["alive_ms"]["max"],
            "cpu_ms_median": f["cpu_ms"]["median"],
        }
        for name, f in report["components"].items()
    ]
    started = [
        {
            "start": name,
            "wall_ms_median": f["wall_ms"]["median"],
            "cpu_ms_median": f["cpu_ms"]["median"],
            "cpu_ms_max": f["cpu_ms"]["max"],
        }
        for name, f in report["starts"].items()
    ]
    return [table(rows) for rows in (alive, started) if rows]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(add_help=False)
    parser.add_argument("--only", default="", help="only the components and starts naming it")
    known, rest = parser.parse_known_args(argv)
    return run_bench(__doc__, partial(measure, only=known.only), lines, 5, rest)


if __name__ == "__main__":
    with result_only_stdout():
        code = main()
    sys.exit(code)
