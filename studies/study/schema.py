"""A study file (YAML): the sweep it declares and the tables its report computes.

Unknown keys are errors, as in a profile; ``load_study`` says what is wrong in one line."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator


class StudyError(ValueError):
    """A study file that cannot be read or is not a study (one line)."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


Gain = float | bool | str


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


class Table(_Strict):
    """One table of the report: a row per group of runs, a column per figure."""

    title: str
    by: list[str]
    """The parameters grouping the runs (``sweep.PARAMETERS``)."""
    figures: list[str]
    """Figures of ``studies.study.figures`` computed over each group's runs."""


class Study(_Strict):
    """A sweep: every robot x goal family (or experiment) x seed x law x goal."""

    name: str = Field(pattern=r"^[a-z0-9][a-z0-9_-]*$")
    description: str = ""
    loop: Literal["kinematic", "simulated"] = "kinematic"
    """A kinematic loop at 50 Hz in the run's process, or the whole simulated loop (its
    processes launched in lockstep, ``parsimony experiment``)."""
    robots: list[str] = ["little_john"]
    """Robots of the zoo (deploy/robots/NAME.yaml) or descriptions' paths (from the file's
    directory)."""
    laws: list[LawSpec]
    families: list[str] = []
    """Goal families of ``studies.goal_families`` (kinematic)."""
    task: Literal["pose", "position"] = "pose"
    goals: int = Field(default=100, ge=1)
    """Goals per family and seed (kinematic)."""
    experiments: list[str] = []
    """Experiments of ``sim2d.scenarios`` (simulated)."""
    seeds: list[int] = Field(min_length=1)
    time_limit_s: float = Field(default=600.0, gt=0)
    """Host seconds one run may take before it counts as hung."""
    tables: list[Table] = []
    page: Path | None = None
    """A docs page (from the repository's root) whose block between the study's markers
    (``report.markers``) its report replaces."""

    @model_validator(mode="after")
    def _what_runs(self) -> Study:
        kinematic = self.loop == "kinematic"
        if kinematic and (not self.families or self.experiments):
            raise ValueError("a kinematic study names families (and no experiments)")
        if not kinematic and (not self.experiments or self.families):
            raise ValueError("a simulated study names experiments (and no families)")
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
