"""`parsimony study FILE`: run a study's sweep (studies/study/) on this machine's cores, or on
a Dask cluster with ``--address``, into its results file, running only the runs it lacks; with
``--report``, its tables from that file."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from outputs.stdout import emit, json_text
from parsimony.stop_signals import Interrupted, stop_signals
from studies.study import results
from studies.study.drive import drive
from studies.study.report import check_tables, markdown, pages, update_page
from studies.study.schema import StudyError, load_study
from studies.study.sweep import expand


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "study",
        help="run a study file's sweep (local cores, or a Dask cluster), resuming where it "
        "stopped; --report: its tables",
    )
    parser.add_argument("file", type=Path, help="the study (YAML), e.g. studies/files/*.yaml")
    parser.add_argument(
        "--address",
        help="a Dask scheduler (tcp://HOST:PORT) whose workers run the runs "
        "(default: a pool of this machine's cores)",
    )
    parser.add_argument(
        "--workers", type=int, help="runs at once on this machine (default: one per core)"
    )
    parser.add_argument(
        "--results",
        type=Path,
        help="its results file (default runs/studies/NAME.parquet; simulated runs' "
        "recordings beside it in NAME/)",
    )
    parser.add_argument(
        "--report", action="store_true", help="print its tables (Markdown) from its results"
    )
    parser.add_argument(
        "--page",
        action="store_true",
        help="with --report, also write them into the study's docs page (its marked block), "
        "and its plots into their files",
    )
    return parser


def run(args: argparse.Namespace) -> int:
    try:
        study = load_study(args.file)
        check_tables(study)
        path = args.results or Path("runs/studies") / f"{study.name}.parquet"
        runs = expand(study, args.file.parent, path.with_suffix(""))
    except StudyError as error:
        print(f"parsimony study: {error}", file=sys.stderr)
        return 2
    if args.workers is not None and args.workers < 1:
        print("parsimony study: --workers must be 1 or more", file=sys.stderr)
        return 2
    if args.report:
        rows = results.read(path)
        text = markdown(study, str(args.file), runs, rows)
        if args.page:
            named = pages(study)
            missing = [
                str(page)
                for page in named
                if not update_page(page, study, markdown(study, str(args.file), runs, rows, page))
            ]
            if missing or not named:
                print(
                    f"parsimony study: {study.name}: no page with its markers "
                    f"({', '.join(missing) or 'it names none'})",
                    file=sys.stderr,
                )
                return 2
            from studies.study.plots import draw

            for plot in study.plots:
                print(f"parsimony study: {draw(study, plot, runs, rows)}", file=sys.stderr)
        emit(text.rstrip("\n"))
        return 0
    if args.address:
        from studies.study.cluster import DaskCluster

        runner = DaskCluster(args.address)
    else:
        from studies.study.local import LocalPool

        runner = LocalPool(args.workers)
    with stop_signals(raising=True):
        try:
            with runner:
                counts = drive(runs, runner, path, study.name)
        except Interrupted as stop:
            print(
                f"parsimony study: stopped by {stop.signal}; the rows done are in {path}, "
                "and running it again runs the others",
                file=sys.stderr,
            )
            return stop.exit_code
    emit(json_text({"study": study.name, "results": str(path), **counts}))
    return 0
