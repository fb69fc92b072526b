"""Where the wall time of one lockstep pose experiment goes, printed (nothing asserted).

    python -m studies.bench.run_breakdown [--law lp] [--runs N] [--processes both] [--json]
                                          [--no-figures]
    python -m studies.bench.run_breakdown --parallel 2 --runs 8      # runs per minute

Each run is ``parsimony experiment pose`` in a process of its own (its profile's ``processes``
as asked; ``both`` alternates them), its progress lines and its launch log stamped. Printed per
mode, medians over the runs: the phases (the experiment's imports and set-up, the launcher's
router up, every component alive, every component reached by the paused clock, the simulated
run, every process stopped, the judgement, the figures), the CPU time of the whole process tree,
and per simulated step the host time of each stage as its component measures it (the median and
p99 of each subscription handler, ``components.pubsub``, and of the lockstep gate's waits,
``components.lockstep_gate``: ``frame`` from a camera frame's publication to its last answer,
``frame_wait`` a step waiting for them, ``loop`` a step waiting for the commands).
With ``--parallel K``, K runs at a time: the whole-loop runs per minute. With ``--no-figures``
the runs draw no figures and each is forked from this process, as a study's runs are (its
launcher forked, ``launch.forked``, and the launcher's fork server, ``launch.fork_server``; this
process opens no Zenoh session); the CPU time is then the run's alone.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from datetime import datetime
from itertools import pairwise
from pathlib import Path
from typing import Any

from launch.forked import Forked, forked
from outputs.stdout import json_text
from studies.experiment import Options, run_experiment

EVENTS = (
    ("set up", "experiment", "starting "),
    ("router up", "launch", "router listening"),
    ("all alive", "launch", "components alive"),
    ("clock reached", "experiment", "running until"),
    ("run ended", "experiment", "stopping the processes"),
    ("all stopped", "launch", "stopped ("),
    ("judged", "experiment", "drawing the figures"),
)
"""Each phase's end: a line of the experiment's progress or of its launch log (the last such
line for ``all stopped``); the figures are written when the run's process exits (without
figures, the run is judged then)."""
STEP_S = 0.02
"""The simulator's step (its ``step_s``)."""


def _stamped(text: str) -> float:
    """A launch log line's ``HH:MM:SS.mmm`` (local time, today) in seconds since the epoch."""
    clock = datetime.strptime(text[:12], "%H:%M:%S.%f").time()
    return datetime.combine(datetime.now().date(), clock).timestamp()


def one_run(law: str, processes: str, out: Path, figures: bool = True) -> dict[str, Any]:
    """One experiment in a process of its own: its phases, CPU and report."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.time()
    command = ["studies.bench.run_breakdown", "--one", str(out), "--law", law]
    command += ["--processes", processes, *([] if figures else ["--no-figures"])]
    pipes = {"stdout": subprocess.PIPE, "stderr": subprocess.PIPE}
    child: subprocess.Popen | Forked
    if figures:  # as the command runs it: a new interpreter
        child = subprocess.Popen([sys.executable, "-m", *command], text=True, **pipes)
    else:  # as a study runs it: forked from this process, its modules loaded
        child = forked(command, **pipes)
    lines: list[tuple[float, str]] = []
    reader = threading.Thread(
        target=lambda: lines.extend((time.time(), text) for text in child.stderr), daemon=True
    )
    reader.start()
    printed = child.stdout.read()
    child.wait()
    reader.join()
    if child.returncode != 0:
        raise RuntimeError(f"the run failed ({child.returncode}): {lines[-1][1] if lines else ''}")
    report = json.loads(printed)
    ended = time.time()
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu_s = sum(getattr(after, f) - getattr(before, f) for f in ("ru_utime", "ru_stime"))
    launch = [(_stamped(t), t[13:]) for t in (out / "launch.log").read_text().splitlines() if t]
    found = {}
    for name, source, text in EVENTS if figures else EVENTS[:-1]:
        stamps = [
            stamp
            for stamp, line in (lines if source == "experiment" else launch)
            if line.startswith(f"[{source}]") and text in line
        ]
        found[name] = stamps[-1] if stamps else float("nan")
    ends = [started, *found.values(), ended]
    names = ["started", *found, "figures written" if figures else "judged"]
    phases = {
        f"{a} -> {b}": round(t1 - t0, 3)
        for (a, t0), (b, t1) in pairwise(zip(names, ends, strict=True))
    }
    return {
        "wall_s": round(ended - started, 3),
        "cpu_tree_s": round(cpu_s, 3),
        "phases": phases,
        "report": report,
    }


def summary(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """The medians over ``runs`` of one mode."""

    def median(values: list[float]) -> float:
        return round(statistics.median(values), 3)

    reports = [run["report"] for run in runs]
    per_step = [r["wall_time_s"] / r["sim_time_s"] * STEP_S * 1e3 for r in reports]
    stages: dict[str, dict[str, float]] = {}
    for name in sorted(reports[0]["durations_us"]):
        for key in reports[0]["durations_us"][name]:
            values = [r["durations_us"].get(name, {}).get(key) for r in reports]
            stages.setdefault(name, {})[key] = median([v for v in values if v is not None])
    return {
        "runs": len(runs),
        "wall_s": median([run["wall_s"] for run in runs]),
        "cpu_tree_s": median([run["cpu_tree_s"] for run in runs]),
        "phases_s": {k: median([run["phases"][k] for run in runs]) for k in runs[0]["phases"]},
        "real_time_factor": median([r["real_time_factor"] for r in reports]),
        "wall_ms_per_step": median(per_step),
        "cpu_ms_per_step": {
            k: median(
                [r["cpu_s"][k] / r["sim_time_s"] * STEP_S * 1e3 for r in reports if k in r["cpu_s"]]
            )
            for k in sorted({k for r in reports for k in r["cpu_s"]})
        },
        "lockstep_timeouts": max(r["lockstep_timeouts"] for r in reports),
        "commands_digests": sorted({r["commands_digest"] for r in reports}),
        "stages_us": stages,
    }


def throughput(
    law: str, modes: list[str], runs: int, parallel: int, root: Path, figures: bool = True
) -> dict:
    """Whole-loop runs per minute with ``parallel`` runs at a time, per mode (alternated:
    a batch of each mode in turn)."""
    done: dict[str, list[float]] = {mode: [] for mode in modes}
    for batch in range(runs):
        mode = modes[batch % len(modes)]
        started = time.monotonic()
        threads = [
            threading.Thread(target=one_run, args=(law, mode, root / f"{batch}-{k}", figures))
            for k in range(parallel)
        ]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        done[mode].append(parallel * 60.0 / (time.monotonic() - started))
    return {mode: round(statistics.median(rates), 2) for mode, rates in done.items()}


def printed(results: dict[str, dict[str, Any]]) -> str:
    lines = []
    for mode, found in results.items():
        lines += [
            f"processes: {mode} ({found['runs']} runs, medians)",
            f"  wall {found['wall_s']:.2f} s, CPU of the process tree {found['cpu_tree_s']:.2f} s,"
            f" real-time factor {found['real_time_factor']}, {found['wall_ms_per_step']:.1f} ms"
            f" of wall time per {STEP_S * 1e3:g} ms step",
        ]
        lines += [f"  {phase:<34} {s:6.2f} s" for phase, s in found["phases_s"].items()]
        cpu = ", ".join(f"{k} {v:.2f}" for k, v in found["cpu_ms_per_step"].items())
        lines.append(f"  CPU per step during the run (ms), each process: {cpu}")
        lines.append("  per step, median / p99 (us):")
        for name, values in found["stages_us"].items():
            keys = sorted({k.rsplit("_us_", 1)[0] for k in values})
            shown = [f"{k} {values[f'{k}_us_median']:g}/{values[f'{k}_us_p99']:g}" for k in keys]
            lines.append(f"    {name}: " + ", ".join(shown))
        lines.append(f"  commands digest {', '.join(found['commands_digests'])}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--law", default="lp", choices=("lp", "qp", "cascade"))
    parser.add_argument(
        "--runs", type=int, default=3, help="runs per mode (batches with --parallel)"
    )
    parser.add_argument("--processes", default="both", choices=("both", "separate", "shared"))
    parser.add_argument("--parallel", type=int, default=0, help="K runs at a time: runs per minute")
    parser.add_argument("--json", action="store_true", help="JSON on stdout")
    parser.add_argument(
        "--no-figures", dest="figures", action="store_false", help="draw none, as a study's runs"
    )
    parser.add_argument("--one", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.one is not None:  # one run, in this process: its report on stdout
        options = Options(
            "pose", args.law, out=args.one, processes=args.processes, figures=args.figures
        )
        print(json_text(run_experiment(options)), flush=True)
        return 0
    modes = ["separate", "shared"] if args.processes == "both" else [args.processes]
    print(f"load average {os.getloadavg()[0]:.2f} before", file=sys.stderr)
    with tempfile.TemporaryDirectory(prefix="run-breakdown-") as root:
        if args.parallel:
            runs = args.runs * len(modes)
            rates = throughput(args.law, modes, runs, args.parallel, Path(root), args.figures)
            result: Any = {"parallel": args.parallel, "runs_per_minute": rates}
            text = f"{args.parallel} at a time, runs per minute (median over batches): {rates}"
        else:
            found: dict[str, list] = {mode: [] for mode in modes}
            for index in range(args.runs * len(modes)):  # the modes alternated
                mode = modes[index % len(modes)]
                found[mode].append(one_run(args.law, mode, Path(root) / str(index), args.figures))
            result = {mode: summary(runs) for mode, runs in found.items()}
            text = printed(result)
    print(f"load average {os.getloadavg()[0]:.2f} after", file=sys.stderr)
    print(json_text(result) if args.json else text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
