"""`parsimony study`: a tiny kinematic study on the local pool and on a real Dask cluster on
loopback (a scheduler and two workers, separate processes) gives the same rows; a second
invocation runs only the rows missing; a hung run is recorded with its reason, retried once,
and the study goes on; the report's table; a bad study file is one line."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from parsimony.cli import main
from studies.study import results
from studies.study.cluster import local_cluster

ROOT = Path(__file__).resolve().parents[3]
TINY = {
    "name": "tiny",
    "families": ["ahead"],
    "goals": 2,
    "seeds": [2],
    "laws": [{"law": "lp"}, {"law": "lp", "label": "lp eta", "gains": {"eta": [0.5]}}],
    "tables": [
        {
            "title": "reach",
            "by": ["family", "law"],
            "figures": ["runs", "failed", "reached inside every limit", "nonzero moving"],
        }
    ],
}


def study_file(directory: Path, **changes: object) -> Path:
    path = directory / "tiny.yaml"
    path.write_text(yaml.safe_dump(TINY | changes))
    return path


def study(capsys, *args: object) -> dict:
    """``parsimony study ARGS`` in this process: its JSON line."""
    code = main(["study", *map(str, args)])
    out = capsys.readouterr().out
    assert code == 0, out
    return json.loads(out)


def findings(path: Path) -> str:
    """The rows without how long they took, as text (a NaN equal to a NaN)."""
    return json.dumps([results.findings(row) for row in results.read(path)], default=str)


@pytest.fixture(scope="module")
def local(tmp_path_factory) -> Path:
    """The tiny study run on the local pool: its results file."""
    directory = tmp_path_factory.mktemp("local")
    path = directory / "tiny.parquet"
    code = main(["study", str(study_file(directory)), "--workers", "2", "--results", str(path)])
    assert code == 0
    return path


@pytest.fixture(scope="module")
def scheduler(tmp_path_factory):
    """A Dask scheduler and two workers on 127.0.0.1, each its own process: the address."""
    with local_cluster(2, tmp_path_factory.mktemp("dask")) as address:
        assert address.startswith("tcp://127.0.0.1:")
        yield address


def test_a_dask_cluster_gives_the_local_pools_rows(local, scheduler, tmp_path, capsys) -> None:
    path = tmp_path / "tiny.parquet"
    counts = study(capsys, study_file(tmp_path), "--address", scheduler, "--results", path)
    assert counts["ran"] == counts["runs"] == 4 and counts["workers"] == 2
    assert findings(path) == findings(local)
    assert {row["status"] for row in results.read(path)} == {"ok"}


def test_a_second_invocation_runs_only_the_missing_rows(local, tmp_path, capsys) -> None:
    path = tmp_path / "tiny.parquet"
    rows = results.read(local)
    results.write(path, rows[1:3])  # two rows lost, as by an interrupted study
    counts = study(capsys, study_file(tmp_path), "--results", path)
    assert (counts["already_there"], counts["ran"]) == (2, 2)
    assert findings(path) == findings(local)
    again = study(capsys, study_file(tmp_path), "--results", path)
    assert again["ran"] == 0


def test_a_hung_run_is_recorded_retried_once_and_the_study_goes_on(tmp_path, capsys) -> None:
    file = study_file(tmp_path, time_limit_s=0.001, laws=[{"law": "lp"}])
    path = tmp_path / "hung.parquet"
    counts = study(capsys, file, "--results", path)
    assert counts["failed"] == counts["runs"] == 2
    for row in results.read(path):
        assert row["status"] == "failed" and row["tries"] == 2
        assert row["reason"] == "hung: no answer within its time limit of 0.001 s"


def test_the_report_is_a_markdown_table_naming_the_study(local, tmp_path, capsys) -> None:
    file = study_file(tmp_path)
    study_text = main(["study", str(file), "--results", str(local), "--report"])
    out = capsys.readouterr().out
    assert study_text == 0
    assert f"parsimony study {file} --report" in out and "4 of 4 runs" in out
    lines = [line for line in out.splitlines() if line.startswith("| ahead")]
    assert [line.split("|")[2].strip() for line in lines] == ["lp", "lp eta, eta=0.5"]
    assert all(line.split("|")[3].strip() == "2" for line in lines)  # runs per law


def test_a_study_naming_an_unknown_law_is_one_line(tmp_path, capsys) -> None:
    file = study_file(tmp_path, laws=[{"law": "lq"}])
    assert main(["study", str(file)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("parsimony study: no kinematic law 'lq'") and "\n" not in err


def test_a_worker_killed_mid_study_loses_no_run(local, scheduler, tmp_path) -> None:
    """Last of the cluster's tests: one of its two workers is killed while it holds a run;
    the study ends with every row, each run to the end."""
    from distributed import Client

    path = tmp_path / "tiny.parquet"
    command = [sys.executable, "-m", "parsimony.cli", "study", str(study_file(tmp_path))]
    command += ["--address", scheduler, "--results", str(path)]
    study = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    with Client(scheduler, timeout="60s") as client:
        deadline = time.monotonic() + 300
        busy: list[str] = []
        while not busy and time.monotonic() < deadline and study.poll() is None:
            busy = [worker for worker, held in client.processing().items() if held]
            time.sleep(0.05)
        assert busy, "no worker was seen holding a run"
        os.kill(client.run(os.getpid, workers=busy[:1])[busy[0]], signal.SIGKILL)
    out, _ = study.communicate(timeout=600)
    assert study.returncode == 0
    assert json.loads(out)["runs"] == 4
    assert findings(path) == findings(local)


def test_a_study_stopped_keeps_its_rows_and_the_next_runs_the_others(
    local, tmp_path, capsys
) -> None:
    """SIGTERM once a run is done: exit 143, the rows done saved; run again, the others ran."""
    path = tmp_path / "tiny.parquet"
    file = study_file(tmp_path)
    command = [sys.executable, "-m", "parsimony.cli", "study", str(file), "--workers", "1"]
    study_run = subprocess.Popen(
        [*command, "--results", str(path)], cwd=ROOT, stderr=subprocess.PIPE, stdout=subprocess.PIPE
    )
    said = b""
    while b" 1/4 " not in said and study_run.poll() is None:  # the progress bar's first run
        said += os.read(study_run.stderr.fileno(), 4096)
    study_run.send_signal(signal.SIGTERM)
    _, err = study_run.communicate(timeout=300)
    assert study_run.returncode == 143, (said + err).decode()[-2000:]
    assert b"stopped by SIGTERM" in err
    kept = len(results.read(path))
    assert 1 <= kept < 4
    counts = study(capsys, file, "--results", path)
    assert (counts["already_there"], counts["ran"]) == (kept, 4 - kept)
    assert findings(path) == findings(local)
