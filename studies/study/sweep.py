"""A study's sweep, run by run: every loop x robot x family (or experiment) x task x seed x
law x goal, in that order, each run seeded by its place in it (the seed, and the goal's index
among that seed's draws), so that it gives the same row wherever and whenever it runs."""

from __future__ import annotations

import hashlib
import itertools
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from profiles.deploy_files import ROBOTS_DIR
from studies.study.schema import Gain, LawSpec, Study, StudyError

PARAMETERS = ("loop", "robot", "family", "experiment", "task", "seed", "goal", "law")
"""A run's parameters a table may group by (``law`` is the law's label; ``loop`` only in a
study of both loops)."""


@dataclass(frozen=True)
class Run:
    """One run of a sweep: its place, its key (what it is, whatever else the file sweeps) and
    what it runs."""

    index: int
    key: str
    loop: str
    robot_file: str
    parameters: dict[str, Any]
    """``PARAMETERS`` and the law's name in ``law_name``, its gains (JSON) in ``gains``."""
    time_limit_s: float
    out: str = ""
    """The run's own directory (a simulated run's recording and report)."""


def laws(spec: LawSpec) -> list[tuple[str, dict[str, Gain]]]:
    """(label, gains) of each law ``spec`` sweeps: one per combination of its listed gains."""
    names = list(spec.gains)
    values = [v if isinstance(v, list) else [v] for v in spec.gains.values()]
    found = []
    for combination in itertools.product(*values):
        gains = dict(zip(names, combination, strict=True))
        swept = [f"{n}={v}" for n, v in gains.items() if isinstance(spec.gains[n], list)]
        label = ", ".join([spec.label or spec.law, *swept])
        found.append((label, gains))
    return found


def expand(study: Study, directory: Path = Path("."), runs_dir: Path = Path("runs")) -> list[Run]:
    """Every run of ``study`` (robot paths from ``directory``, a directory of its own in
    ``runs_dir`` for each simulated run); ``StudyError`` naming the first
    robot, family, experiment, law or gain it does not know, before anything runs."""
    from studies.study.places import check_law, kind

    runs: list[Run] = []
    checked: set[tuple] = set()
    places = study.families or study.experiments
    place_name = "family" if study.families else "experiment"
    tasks = study.tasks if study.families else [None]
    for loop in study.loops:
        kinds = {kind(loop, place) for place in places}
        if len(kinds) > 1:
            raise StudyError(f"{', '.join(places)}: places of one kind only ({', '.join(kinds)})")
        for robot, place, task in itertools.product(study.robots, places, tasks):
            path = _robot(robot, directory)
            for seed, spec in itertools.product(study.seeds_of(loop), study.laws):
                if spec.only and place not in spec.only:
                    continue
                if task is not None and task not in spec.tasks_of(study.tasks):
                    continue
                for label, gains in laws(spec):
                    law_key = (loop, place, spec.law, json.dumps(gains, sort_keys=True), path)
                    if law_key not in checked:  # once per law, not per run
                        check_law(kind(loop, place), spec.law, gains, place, path)
                        checked.add(law_key)
                    goals = range(study.goals) if study.families else [None]
                    for goal in goals:
                        parameters = {
                            **({"loop": loop} if len(study.loops) > 1 else {}),
                            "robot": Path(robot).stem,
                            place_name: place,
                            "task": task,
                            "seed": seed,
                            "goal": goal,
                            "law": label,
                            "law_name": spec.law,
                            "gains": json.dumps(gains, sort_keys=True),
                        }
                        key = json.dumps([parameters[n] for n in PARAMETERS if n in parameters])
                        out = runs_dir / hashlib.sha1(key.encode()).hexdigest()[:12]
                        simulated = loop == "simulated"
                        runs.append(
                            Run(
                                len(runs),
                                key,
                                loop,
                                str(path),
                                parameters,
                                study.time_limit_s,
                                str(out) if simulated else "",
                            )
                        )
    keys = [run.key for run in runs]
    if len(set(keys)) != len(keys):
        raise StudyError(
            "two runs of the sweep are the same run: give the laws labels of their own"
        )
    return runs


def _robot(text: str, directory: Path) -> Path:
    """A robot of the zoo by name, or a description's path from ``directory``."""
    path = Path(text)
    named = path.suffix not in (".yaml", ".yml") and len(path.parts) == 1
    path = ROBOTS_DIR / f"{text}.yaml" if named else directory / path
    if not path.is_file():
        raise StudyError(f"no robot {text!r}: neither a robot of {ROBOTS_DIR} nor a file")
    return path.resolve()
