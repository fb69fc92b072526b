"""The rows of two future works of section 7.2: the LP against the QP of the same rows and
terms (5), and the LP with its input change term against without (1)."""

from __future__ import annotations

from dataclasses import astuple

from studies.reproduce import laws as L
from studies.reproduce.measures import entry_counts
from studies.reproduce.runs import Experiment
from studies.reproduce.table import Row
from wbc.laws.kinematic_run import control_effort


def qp_rows(experiment: Experiment) -> list[Row]:
    """Future work 5: iterations, nonzero entries [of u, x' y' as one] while moving, and table
    6.1's four metrics of the LP and the QP and their ratio."""
    name = experiment.name
    runs = {label: experiment.runs[label] for label in (L.LP, L.QP)}
    metrics = {label: list(astuple(control_effort(run))) for label, run in runs.items()}
    return [
        Row(
            f"{name}.qp.entries",
            "7.2 (5)",
            f"{name}: {L.LP} against {L.QP}, iterations; "
            "nonzero entries [of u, x' y' as one] while moving",
            "not done",
            {label: [len(run.outputs), entry_counts(run)["moving"]] for label, run in runs.items()},
            "LP sparser",
            name,
            (L.LP, L.QP),
        ),
        Row(
            f"{name}.qp.metrics",
            "7.2 (5)",
            f"{name}: {L.LP}, {L.QP}, {L.LP} / {L.QP}, metrics 1-4",
            "not done",
            {
                **metrics,
                "LP/QP": [a / b for a, b in zip(metrics[L.LP], metrics[L.QP], strict=True)],
            },
            experiment=name,
            laws=(L.LP, L.QP),
        ),
    ]


def input_change_rows(experiment: Experiment) -> list[Row]:
    """Future work 1: iterations and nonzero entries (while moving, last 2 s), then table 6.1's
    metrics with the term and without, and their ratio, as the run takes them, and 3 and 4
    from rest (u = 0 before the first command, as in a recording)."""
    name = experiment.name
    runs = {label: experiment.runs[label] for label in (L.LP_INPUT_CHANGE, L.LP)}
    found = {}
    for from_rest in (False, True):
        with_term, without = (
            list(astuple(control_effort(run, from_rest)))[2 * from_rest :] for run in runs.values()
        )
        found["from rest" if from_rest else "as run"] = {
            "with": with_term,
            "LP": without,
            "ratio": [a / b for a, b in zip(with_term, without, strict=True)],
        }
    return [
        Row(
            f"{name}.input_change.entries",
            "7.2 (1)",
            f"{name}: {L.LP_INPUT_CHANGE} against "
            f"{L.LP}, iterations; nonzero entries [of u, x' y' as one]",
            "not done",
            {label: [len(run.outputs), entry_counts(run)] for label, run in runs.items()},
            "the same entries",
            name,
            (L.LP_INPUT_CHANGE, L.LP),
        ),
        Row(
            f"{name}.input_change.metrics",
            "7.2 (1)",
            f"{name}: {L.LP_INPUT_CHANGE} (with), "
            f"{L.LP} and their ratio, metrics 1-4; 3 and 4 from rest",
            "not done",
            found,
            "ratio of 3 and 4 < 1",
            name,
            (L.LP_INPUT_CHANGE, L.LP),
        ),
    ]
