"""`parsimony report FILE [FILE2] --out DIR`: the chapter 6 figures and table 6.1 of recorded
sessions (see analysis.report), and each run judged from its file (analysis.judge) into
``DIR/judged.json``: what ``parsimony experiment`` wrote into its report.json of the same
file."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from analysis.judge import JUDGED, judge, open_loop
from analysis.report import write_report
from analysis.run_end import the_run
from outputs.stdout import emit, json_text
from parsimony.argument_types import positive_seconds
from parsimony.commands.robot_option import add_robot_option
from profiles.profile import ProfileError, load_profile
from record.session_span import parted
from record.sessions import load_session
from wbc.robot import MobileManipulator


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "report",
        help="figures like 6.6 to 6.14 and table 6.1 of one or two recordings",
        description="Write PNG figures (control inputs, nonzero entries, the error's eight "
        "coefficients, joints against their limits, end-effector and base paths with the "
        "obstacles, the arm's clearance from the solids in 3-D) and the four "
        "effort metrics of table 6.1 (JSON and Markdown) into DIR; two files side by side.",
    )
    parser.add_argument("files", type=Path, nargs="+", metavar="FILE", help="MCAP sessions")
    parser.add_argument("--labels", help="comma-separated labels (default: the law's name)")
    parser.add_argument("--out", type=Path, required=True, help="directory of the figures")
    add_robot_option(parser)
    parser.add_argument(
        "--profile", type=Path, help="the recorded profile: truth drawn in F0's frame"
    )
    parser.add_argument(
        "--time-limit",
        type=positive_seconds,
        metavar="S",
        help="a run that did not converge ends S s after its start, as "
        "`experiment --time-limit` ended it (default: at its last step)",
    )
    parser.add_argument("--json", action="store_true", help="print the result as JSON")
    return parser


def run(args: argparse.Namespace) -> int:
    if len(args.files) > 2:
        print("report: one or two files", file=sys.stderr)
        return 2
    loaded, sessions = [], []
    try:
        labels = labels_given(args.labels, len(args.files))
        robot = MobileManipulator.from_yaml(args.robot)
        frame = None
        if args.profile is not None:
            scene = load_profile(args.profile).scene
            frame = scene.reference_pose if scene is not None else None
        for index, path in enumerate(args.files):
            loaded.append(load_session(path, JUDGED))
            if outside := parted(loaded[-1]).line():
                print(f"report: {path}: left out, {outside}", file=sys.stderr)
            session = the_run(loaded[-1], args.time_limit)[0]
            sessions.append((labels[index] if labels else label_of(session, path), session))
        args.out.mkdir(parents=True, exist_ok=True)
        result = write_report(sessions, robot, args.out, frame)
        judged = {
            label: judge(whole, robot, args.time_limit)
            for (label, _), whole in zip(sessions, loaded, strict=True)
        }
    except (OSError, ValueError, ProfileError) as error:
        print(f"report: {error}", file=sys.stderr)
        return 2
    for name, why in result["gaps"].items():
        print(f"report: {name} not drawn: {why}", file=sys.stderr)
    for note in result["notes"]:
        print(f"report: note: {note}", file=sys.stderr)
    (args.out / "judged.json").write_text(json_text(judged, indent=2) + "\n")
    result = {**result, "figures": [str(p) for p in result["figures"]], "judged": judged}
    emit(json_text(result, indent=2) if args.json else "\n".join(result["figures"]))
    return 0


def labels_given(labels: str | None, files: int) -> list[str]:
    """The user's labels, one per file (``ValueError`` otherwise); empty when not given."""
    if labels is None:
        return []
    given = [label.strip() for label in labels.split(",")]
    if len(given) != files or not all(given):
        raise ValueError(
            f"--labels: expected {files} non-empty comma-separated label"
            f"{'s' * (files > 1)}, got {labels!r}"
        )
    return given


def label_of(session: dict, path: Path) -> str:
    """The law that made the recording (``(rerun)`` after it for a rerun's), else the file's
    name."""
    diagnostics = session.get("control/diagnostics") or []
    if not diagnostics:
        return path.stem
    return diagnostics[0].law + (" (rerun)" if open_loop(session) else "")
