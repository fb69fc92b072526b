"""The figures a study's tables compute over a group of runs, by name, each from the
functions that compute it for the benchmarks (``studies.goal_sets``' shares, parsimony,
failures and planning; an experiment's summary): none is computed anew here."""

from __future__ import annotations

import json
import re
import statistics
from collections import Counter
from collections.abc import Callable
from typing import Any

import numpy as np

from studies import redundancy
from studies.goal_sets import failures, not_reached, parsimony, planning, shares
from studies.study.execute import OK
from studies.study.runs import attempt_of
from wbc import dq
from wbc.planar import wrap
from wbc.robot import MobileManipulator

Rows = list[dict[str, Any]]
Figure = Callable[[Rows, MobileManipulator], dict[str, Any]]

FOLDED = 0.2
"""A goal's gripper this near its base, horizontally (m), has the arm bent back over it."""
HEADING_OFF = 0.5
"""How far (rad) a missed run's base heading may end from the goal configuration's unremarked."""


def ok(rows: Rows) -> Rows:
    return [row for row in rows if row["status"] == OK]


def _attempts(rows: Rows) -> list:
    return [attempt_of(row) for row in ok(rows)]


def _share(name: str, key: str) -> Figure:
    return lambda rows, robot: {name: shares(_attempts(rows))[key]}


def _parsimony(name: str, key: str) -> Figure:
    return lambda rows, robot: {name: parsimony(_attempts(rows), robot.dof)[key]}


def _sets(rows: Rows, robot: MobileManipulator) -> dict[str, Any]:
    """The worst and the best seed's share reached inside every limit."""
    seeds = sorted({row["seed"] for row in rows})
    each = [
        shares(_attempts([r for r in rows if r["seed"] == s]))["within_joint_and_speed_limits"]
        for s in seeds
    ]
    return {"worst set": min(each), "best set": max(each)}


def misses(rows: Rows, robot: MobileManipulator) -> dict[str, int]:
    """The goals not reached inside every limit, by kind (a goal may be of several)."""
    kinds: Counter[str] = Counter()
    for row in ok(rows):
        a, goal = attempt_of(row), np.asarray(row["goal_q"])
        if a.within_all_limits:
            continue
        kinds["missed"] += 1
        gripper = dq.translation(robot.fkm(goal))[1:3]
        kinds["gripper over its base"] += bool(np.hypot(*(gripper - goal[:2])) < FOLDED)
        edge = a.reason.partition(", ")[2].removesuffix(" at the joint box's edge")
        kinds[f"{edge} at its box's edge"] += edge.startswith("q")
        turned = a.last is not None and abs(wrap(float(a.last[2] - goal[2]))) > HEADING_OFF
        kinds["base heading off"] += turned
    return {"missed": 0} | {kind: n for kind, n in kinds.items() if n}


def _effort(rows: Rows, robot: MobileManipulator) -> dict[str, float]:
    """Table 6.1's metrics, from rest, the median over the runs."""
    efforts = [a.effort_from_rest for a in _attempts(rows) if a.effort_from_rest is not None]
    names = ("velocity_l1", "velocity_l2", "acceleration_l1", "acceleration_l2")
    return {n: float(np.median([getattr(e, n) for e in efforts])) for n in names if efforts}


def by_kind(reasons: list[str]) -> dict[str, int]:
    """Reasons counted by kind: a reason's head (before a colon), without the counts in
    parentheses, so that it names a kind of miss, not one goal's."""
    return dict(Counter(re.sub(r" \(\d+\)", "", r.partition(": ")[0]) for r in reasons))


def _not_reached(rows: Rows, robot: MobileManipulator) -> dict[str, int]:
    """The goals not reached, by the kind of their reason (``by_kind``)."""
    failures = not_reached(_attempts(rows))["failures"]
    return by_kind([reason for reason, n in failures.items() for _ in range(n)])


COMMON: dict[str, Figure] = {
    "runs": lambda rows, robot: {"runs": len(rows)},
    "failed": lambda rows, robot: {"failed": len(rows) - len(ok(rows))},
    "seeds": lambda rows, robot: {"seeds": ",".join(map(str, sorted({r["seed"] for r in rows})))},
}
"""Figures of every study."""
KINEMATIC: dict[str, Figure] = COMMON | {
    "reached": _share("reached", "reached"),
    "reached inside the joint limits": _share(
        "reached inside the joint limits", "within_joint_limits"
    ),
    "reached inside every limit": _share(
        "reached inside every limit", "within_joint_and_speed_limits"
    ),
    "time to converge": _share("time to converge (s)", "median_time_to_converge_s"),
    "every step optimal": _share("every step optimal", "every_step_optimal"),
    "sets": _sets,
    "nonzero moving": _parsimony("nonzero moving", "median_nonzero_moving"),
    "nonzero near the goal": _parsimony("nonzero near the goal", "median_nonzero_settling"),
    "nonzero near the goal, x' y' as one": _parsimony(
        "nonzero near the goal, x' y' as one", "median_nonzero_settling_forward_as_one"
    ),
    "contacts": lambda rows, robot: {"contacts": failures(_attempts(rows))["contacts"]},
    "clearance": lambda rows, robot: {
        "least clearance (m)": failures(_attempts(rows))["least_clearance_m"]
    },
    "planning": lambda rows, robot: planning(_attempts(rows)),
    "effort": _effort,
    "misses": misses,
    "not reached": _not_reached,
}
"""A kinematic study's figures on goal families: each gives one or more columns."""


def median_of(reports: list[dict], component: str, counter: str) -> int:
    return round(
        statistics.median(r["durations_us"].get(component, {}).get(counter, 0) for r in reports)
    )


def summary(name: str, controller: str, found: list[dict | None]) -> dict:
    """Every seed of one experiment and law, summarised (those that could not run counted)."""
    reports = [r for r in found if r is not None]
    estimator = [r["estimator_error"] for r in reports if r["estimator_error"]["samples"]]
    # The recorder's CPU per simulated second: its share of one core in real time (30 Hz).
    recorder = [r["cpu_s"].get("recorder", 0.0) / r["sim_time_s"] for r in reports]
    return {
        "experiment": name,
        "law": controller,
        "runs": len(reports),
        "did_not_run": len(found) - len(reports),
        "converged": sum(r["converged"] for r in reports),
        "with_contact": sum(r["contacts"] > 0 for r in reports),
        "at_joint_stops": sum(r["joint_limit_violations"] > 0 for r in reports),
        "estimator_position_mm": round(max(e["position_m"] for e in estimator) * 1e3, 2),
        "estimator_angle_deg": round(float(np.degrees(max(e["angle_rad"] for e in estimator))), 2),
        "real_time_factor": round(statistics.median(r["real_time_factor"] for r in reports), 2),
        "rtf_min": round(min(r["real_time_factor"] for r in reports), 2),
        "tracker_frame_us": median_of(reports, "vision_tracker", "handler.camera/image_us_median"),
        "estimator_odometry_us": median_of(
            reports, "state_estimator", "handler.base/odometry_us_median"
        ),
        "controller_state_us": median_of(reports, "controller", "handler.robot/state_us_median"),
        "frame_answer_us": median_of(reports, "simulator", "frame_us_median"),
        "loop_us": median_of(reports, "simulator", "loop_us_median"),
        "recorder_cpu_pct_rt": round(100 * statistics.median(recorder), 1),
        "bytes_per_sim_s": round(
            statistics.median(r["recording"]["bytes_per_sim_s"] for r in reports)
        ),
        "recordings_whole": sum(r["recording"]["whole"] for r in reports),
    }


def _summary(key: str) -> Figure:
    def figure(rows: Rows, robot: MobileManipulator) -> dict[str, Any]:
        reports = [json.loads(r["report"]) if r["status"] == OK else None for r in rows]
        if not any(reports):
            return {key: None}
        return {key: summary(rows[0]["experiment"], rows[0]["law_name"], reports)[key]}

    return figure


SIMULATED_COLUMNS = (
    "runs",
    "did_not_run",
    "converged",
    "with_contact",
    "at_joint_stops",
    "estimator_position_mm",
    "estimator_angle_deg",
    "real_time_factor",
    "rtf_min",
    "tracker_frame_us",
    "estimator_odometry_us",
    "controller_state_us",
    "frame_answer_us",
    "loop_us",
    "recorder_cpu_pct_rt",
    "bytes_per_sim_s",
    "recordings_whole",
)
"""The columns of ``summary`` a simulated study's table may name."""


def _reports(rows: Rows) -> list[dict]:
    return [json.loads(r["report"]) for r in ok(rows)]


def _arm_penetrations(rows: Rows, robot: MobileManipulator) -> dict[str, int]:
    """The runs in which a part of the arm entered a solid (the judge's ``arm_penetrations``)."""
    return {
        "with an arm penetration": sum((r["arm_penetrations"] or 0) > 0 for r in _reports(rows))
    }


def _arm_clearance(rows: Rows, robot: MobileManipulator) -> dict[str, float]:
    """Each collision part's least clearance from the solids over the runs, m (negative: the
    deepest penetration; the judge's ``arm_clearance_m``)."""
    least: dict[str, float] = {}
    for report in _reports(rows):
        for part, clearance in (report["arm_clearance_m"] or {}).items():
            least[part] = min(least.get(part, clearance), clearance)
    return {f"{part} (m)": value for part, value in least.items()}


def _supervisor_reasons(rows: Rows, robot: MobileManipulator) -> dict[str, int]:
    """The runs that did not converge, by the kind of the staging supervisor's reason
    (``by_kind``; runs without a supervisor, or without a reason, are not counted)."""
    reports = [r for r in _reports(rows) if not r["converged"]]
    return by_kind(
        [r["supervisor"]["reason"] for r in reports if (r["supervisor"] or {}).get("reason")]
    )


SIMULATED: dict[str, Figure] = {key: _summary(key) for key in SIMULATED_COLUMNS} | {
    "arm penetrations": _arm_penetrations,
    "arm clearance": _arm_clearance,
    "not reached": _supervisor_reasons,
}
"""A simulated study's figures (``SETUP``'s too): the experiments' summary's columns, the runs
with an arm penetration, each part's least clearance from the solids, and the runs not
converged by the supervisor's reason."""


def _converge_times(rows: Rows, robot: MobileManipulator) -> dict[str, float | None]:
    """The median and p99 time to converge of the runs that converged, s."""
    times = [r["converge_s"] for r in ok(rows) if r["converged"]]
    if not times:
        return {"time to converge, median (s)": None, "p99 (s)": None}
    return {
        "time to converge, median (s)": round(float(np.median(times)), 1),
        "p99 (s)": round(float(np.percentile(times, 99)), 1),
    }


def _not_converged(rows: Rows, robot: MobileManipulator) -> dict[str, str]:
    """The seeds that did not converge, each with its final error ('every seed' and their
    range when none did)."""
    runs = ok(rows)
    missed = [r for r in runs if not r["converged"]]
    if runs and len(missed) == len(runs) and len(runs) > 1:
        errors = [r["final_error"] for r in missed]
        return {"not converged (final error)": f"every seed ({min(errors):.2f}-{max(errors):.2f})"}
    text = ", ".join(f"{r['seed']} ({r['final_error']:.2f})" for r in missed)
    return {"not converged (final error)": text}


def _nonzero_moving(rows: Rows, robot: MobileManipulator) -> dict[str, float | None]:
    """The median nonzero entries of u over every step of every run with ``||e||`` above
    ``MOVING_ERROR`` (pooled, as ``studies.goal_sets.parsimony`` counts them)."""
    counts = [n for r in ok(rows) for n in r["nonzero_moving"]]
    return {"nonzero moving": float(np.median(counts)) if counts else None}


SETUP: dict[str, Figure] = COMMON | {
    "converged": lambda rows, robot: {
        "converged": round(sum(r["converged"] for r in ok(rows)) / max(len(ok(rows)), 1), 3)
    },
    "with a contact": lambda rows, robot: {
        "with a contact": sum(r["contacts"] > 0 for r in ok(rows))
    },
    "least clearance": lambda rows, robot: {
        "least clearance (m)": min((r["min_obstacle_clearance_m"] for r in ok(rows)), default=None)
    },
    "nonzero moving": _nonzero_moving,
    "time to converge": _converge_times,
    "not converged": _not_converged,
}
"""The figures of runs of an experiment's set-up, on either loop (``runs.SETUP_COLUMNS``):
the share converged, the runs with a contact, the least clearance, the nonzero entries while
moving, the time to converge of those that converged and the seeds that did not."""


def _zoo(name: str, key: str) -> Figure:
    def figure(rows: Rows, robot: MobileManipulator) -> dict[str, Any]:
        outcomes = [
            redundancy.Outcome(
                r["reached"],
                r["within_limits"],
                r["seconds"],
                np.asarray(r["nonzero"], np.int16),
                np.asarray(r["engaged"], np.int16),
                np.asarray(r["error"]),
            )
            for r in ok(rows)
        ]
        return {name: redundancy.summary(outcomes, redundancy.TASKS[rows[0]["task"]])[key]}

    return figure


ZOO: dict[str, Figure] = COMMON | {
    "base": lambda rows, robot: {"base": robot.base.kind},
    "dof": lambda rows, robot: {"dof": robot.dof},
    "entries": lambda rows, robot: {"entries": redundancy.entries(robot)},
    **{
        name: _zoo(name, key)
        for name, key in (
            ("reached in limits", "reached_within_limits"),
            ("reached", "reached"),
            ("nonzero moving", "nonzero_moving"),
            ("nonzero near", "nonzero_near"),
            ("engaged moving", "engaged_moving"),
            ("engaged near", "engaged_near"),
            ("<= task + engaged", "within_bound"),
        )
    },
}
"""The zoo's figures (``studies.redundancy.summary``), and the robot's base, DOF and entries
of u it can move (``studies.redundancy.entries``)."""

METRICS = {
    "metric 3": ("acceleration_l1", "effort"),
    "metric 4": ("acceleration_l2", "effort"),
    "metric 3 from rest": ("acceleration_l1", "effort_from_rest"),
    "metric 4 from rest": ("acceleration_l2", "effort_from_rest"),
}
"""Table 6.1's metrics compared goal by goal: a ``ControlEffort`` field, from the first
command (``effort``, as table 6.1 takes them) or from rest."""
GOAL = ("robot", "family", "task", "seed", "goal")
"""What names one goal of a kinematic study."""


def _effort_against(rows: Rows, reference: Rows, robot: MobileManipulator) -> dict[str, Any]:
    """On the goals both these runs and ``reference`` reached inside every limit: how many,
    and each metric's median and the median of its ratio to the reference's, goal by goal."""
    theirs = {tuple(r[n] for n in GOAL): attempt_of(r) for r in ok(reference)}
    pairs = [
        (a, theirs[key])
        for r in ok(rows)
        if (key := tuple(r[n] for n in GOAL)) in theirs
        and (a := attempt_of(r)).within_all_limits
        and theirs[key].within_all_limits
    ]
    found: dict[str, Any] = {"goals compared": len(pairs)}
    for label, (field, part) in METRICS.items():
        mine = [getattr(getattr(a, part), field) for a, _ in pairs]
        ratios = [
            m / getattr(getattr(b, part), field) for m, (_, b) in zip(mine, pairs, strict=True)
        ]
        found[label] = float(np.median(mine)) if mine else None
        found[f"{label}, ratio"] = float(np.median(ratios)) if ratios else None
    return found


Compared = Callable[[Rows, Rows, MobileManipulator], dict[str, Any]]
COMPARED: dict[str, Compared] = {"effort against": _effort_against}
"""Figures of a kinematic table with ``against``: each group's runs beside that law's runs of
the same goals."""
