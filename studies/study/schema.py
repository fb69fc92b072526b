"""A study file (YAML): the sweep it declares and the tables its report computes.

Unknown keys are errors, as in a profile; ``load_study`` says what is wrong in one line."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal

import yaml
from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationError,
    model_validator,
)


class StudyError(ValueError):
    """A study file that cannot be read or is not a study (one line)."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


Gain = float | bool | str
Task = Literal["pose", "position"]
Loop = Literal["kinematic", "simulated"]


def seed_list(values: list[int | str]) -> list[int]:
    """Seeds as given, a text ``A-B`` standing for A, A+1, ..., B."""
    seeds: list[int] = []
    for value in values:
        if isinstance(value, int):
            seeds.append(value)
            continue
        first, dash, last = value.partition("-")
        if not (dash and first.isdigit() and last.isdigit() and int(first) <= int(last)):
            raise ValueError(f"{value!r} is neither a seed nor a range A-B of seeds")
        seeds += range(int(first), int(last) + 1)
    return seeds


Seeds = Annotated[list[int], BeforeValidator(seed_list)]


class LawSpec(_Strict):
    """One law of the sweep: a law of ``studies.goal_sets.LAWS`` (kinematic) or a controller of
    ``studies.experiment.PROFILES`` (simulated), with gains changed; a gain given as a list is
    swept, each value (or each combination of the lists) a law of its own."""

    law: str
    label: str | None = None
    """Its name in the tables (the law's by default)."""
    gains: dict[str, Gain | list[Gain]] = Field(default_factory=dict)
    only: list[str] = []
    """The families or experiments it runs on (all by default)."""
    task: Task | list[Task] | None = None
    """The tasks it runs (the study's by default), kinematic."""

    def tasks_of(self, study_tasks: list[str]) -> list[str]:
        """The study's tasks this law runs."""
        if self.task is None:
            return study_tasks
        mine = self.task if isinstance(self.task, list) else [self.task]
        return [task for task in study_tasks if task in mine]


class Table(_Strict):
    """One table of the report: a row per group of runs, a column per figure."""

    title: str
    by: list[str]
    """The parameters grouping the runs (``sweep.PARAMETERS``)."""
    figures: list[str]
    """Figures of ``studies.study.figures`` computed over each group's runs."""
    seeds: Seeds = []
    """The seeds whose runs it counts (every seed by default)."""
    where: dict[str, list[int | str]] = {}
    """Parameters (``sweep.PARAMETERS``) and the values of them whose runs it counts (every
    run by default): ``{law: [LP, QP], task: [pose]}``."""
    against: str | None = None
    """A law's label: the figures that compare goal by goal (``figures.COMPARED``) compare
    each group's runs with that law's runs of the same goals."""
    page: Path | None = None
    """The docs page it goes in (the study's ``page`` by default)."""


class Plot(_Strict):
    """A figure of the report (PNG): a point per group of runs (``by``), figure ``x`` against
    each figure of ``y``, a line per value of ``lines`` and a panel per value of ``panels``."""

    file: Path
    """Where it is written, from the repository's root."""
    by: list[str]
    x: str
    y: list[str]
    lines: str = "law"
    panels: str = "task"
    diagonal: str = ""
    """A grey line y = x with this label (empty: none)."""


class Study(_Strict):
    """A sweep: every robot x goal family (or experiment) x seed x law x goal."""

    name: str = Field(pattern=r"^[a-z0-9][a-z0-9_-]*$")
    description: str = ""
    loop: Loop | list[Loop] = "kinematic"
    """A kinematic loop at 50 Hz in the run's process, or the whole simulated loop (its
    processes launched in lockstep, ``parsimony experiment``); both (a list, of experiments
    only) runs each set-up on each, the loop a parameter of the runs."""
    robots: list[str] = ["little_john"]
    """Robots of the zoo (deploy/robots/NAME.yaml) or descriptions' paths (from the file's
    directory)."""
    laws: list[LawSpec]
    families: list[str] = []
    """Goal families of ``studies.goal_families``, or the zoo's goals of
    ``studies.redundancy`` (``zoo``) (kinematic)."""
    task: Task | list[Task] = "pose"
    """The goals' task (a list is swept), kinematic."""
    goals: int = Field(default=100, ge=1)
    """Goals per family and seed (kinematic)."""
    experiments: list[str] = []
    """Experiments of ``sim2d.scenarios``: on the whole loop (simulated), or their set-ups
    run kinematically with the experiment's law (kinematic)."""
    seeds: Seeds | dict[Loop, Seeds] = Field(min_length=1)
    """The seeds, or each loop's."""
    time_limit_s: float = Field(default=600.0, gt=0)
    """Host seconds one run may take before it counts as hung."""
    tables: list[Table] = []
    plots: list[Plot] = []
    page: Path | None = None
    """A docs page (from the repository's root) whose block between the study's markers
    (``report.markers``) its report replaces with its tables (those of a table's own ``page``
    go in that page's block)."""

    @property
    def tasks(self) -> list[str]:
        return self.task if isinstance(self.task, list) else [self.task]

    @property
    def loops(self) -> list[str]:
        return self.loop if isinstance(self.loop, list) else [self.loop]

    def seeds_of(self, loop: str) -> list[int]:
        return self.seeds.get(loop, []) if isinstance(self.seeds, dict) else self.seeds

    @model_validator(mode="after")
    def _what_runs(self) -> Study:
        for loop in self.loops:
            if loop == "kinematic" and bool(self.families) == bool(self.experiments):
                raise ValueError("a kinematic study names families or experiments (not both)")
            if loop == "simulated" and (not self.experiments or self.families):
                raise ValueError("a simulated study names experiments (and no families)")
            if not self.seeds_of(loop):
                raise ValueError(f"no seeds for the {loop} loop")
        for spec in self.laws:
            if spec.task is not None and not self.families:
                raise ValueError(f"law {spec.law!r}: a task of its own needs goal families")
            if not spec.tasks_of(self.tasks):
                raise ValueError(f"law {spec.law!r}: none of its tasks is the study's")
        return self


def load_study(path: Path) -> Study:
    """The study of ``path``; ``StudyError`` in one line when it is not one."""
    try:
        data = yaml.safe_load(Path(path).read_text())
    except (OSError, yaml.YAMLError) as error:
        raise StudyError(f"{path}: {error}".splitlines()[0]) from None
    try:
        return Study.model_validate(data)
    except ValidationError as error:
        first = error.errors()[0]
        where = ".".join(map(str, first["loc"])) or "the file"
        raise StudyError(f"{path}: {where}: {first['msg']}") from None
