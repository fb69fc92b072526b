"""The goal reach study's figures (studies/files/goal-reach.yaml): a row per family and law, the
share reached inside every limit, its worst and best set, and the misses said by kind."""

from __future__ import annotations

from pathlib import Path

import yaml

from parsimony.cli import main
from studies.study import results
from studies.study.figures import KINEMATIC
from wbc.robot import MobileManipulator

ROOT = Path(__file__).resolve().parents[3]
STUDY = yaml.safe_load((ROOT / "studies/files/goal-reach.yaml").read_text())


def test_the_lp_alone_misses_a_goal_over_its_base_that_the_supervised_lp_reaches(
    tmp_path,
) -> None:
    """Goals with the arm bent back over the base: the LP alone misses one of the four of
    seed 2, its base turned away, where the supervised LP reaches all."""
    laws = [STUDY["laws"][0], STUDY["laws"][2]]
    small = STUDY | {"families": ["ahead, wide arm"], "seeds": [2], "goals": 4, "laws": laws}
    file = tmp_path / "goal-reach.yaml"
    file.write_text(yaml.safe_dump(small | {"page": None}))
    path = tmp_path / "goal-reach.parquet"
    assert main(["study", str(file), "--workers", "2", "--results", str(path)]) == 0
    rows = results.read(path)
    robot = MobileManipulator.from_yaml(ROOT / "deploy/robots/little_john.yaml")
    found = {}
    for law in ("LP (default)", "LP + staging supervisor"):
        group = [row for row in rows if row["law"] == law]
        found[law] = {
            name: value
            for figure in ("runs", "reached inside every limit", "sets", "nonzero moving", "misses")
            for name, value in KINEMATIC[figure](group, robot).items()
        }
    lp, supervised = found["LP (default)"], found["LP + staging supervisor"]
    assert lp["runs"] == supervised["runs"] == 4
    assert lp["reached inside every limit"] == lp["worst set"] == 0.75
    assert lp["missed"] == 1 and lp["base heading off"] == 1
    assert lp["nonzero moving"] <= 7
    assert supervised["reached inside every limit"] == 1.0 and supervised["missed"] == 0


def test_a_gain_value_the_lp_refuses_is_one_line(tmp_path, capsys) -> None:
    laws = [{"law": "lp", "gains": {"base_target_stop": -1}}]
    file = tmp_path / "bad.yaml"
    file.write_text(yaml.safe_dump(STUDY | {"laws": laws, "page": None}))
    assert main(["study", str(file)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "base_target_stop" in err, err
