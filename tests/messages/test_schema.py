"""JSON Schemas of the messages, and the `parsimony schema` command."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from messages import FORMAT_TAG, FORMAT_VERSION, MESSAGE_TYPES, TOPICS
from messages.base import Message
from messages.schema import export_schemas, json_schema, schema_index
from parsimony import cli


@pytest.fixture
def schema_only_cli(monkeypatch: pytest.MonkeyPatch) -> None:
    """The real CLI with only the `schema` subcommand, so these tests do not
    depend on the other subcommands being importable."""
    monkeypatch.setattr(cli, "COMMANDS", ("schema",))


@pytest.mark.parametrize("message_type", MESSAGE_TYPES, ids=lambda t: t.__name__)
def test_every_schema_describes_exactly_the_model_fields(message_type: type[Message]) -> None:
    schema = json_schema(message_type)
    assert schema["title"] == message_type.__name__
    assert schema["type"] == "object"
    assert schema["additionalProperties"] is False
    assert list(schema["properties"]) == list(message_type.model_fields)


def test_index_maps_every_topic_suffix_to_its_type() -> None:
    index = schema_index()
    assert index["format_tag"] == FORMAT_TAG
    assert index["format_version"] == FORMAT_VERSION
    assert index["topics"] == {t.suffix: t.type.__name__ for t in TOPICS.values()}
    assert index["keys"] == {"component/*/status": "ComponentStatus"}
    assert set(index["types"]) == {t.__name__ for t in MESSAGE_TYPES}


def test_export_writes_one_schema_per_type_and_the_index(tmp_path: Path) -> None:
    written = export_schemas(tmp_path / "schemas")
    assert sorted(p.name for p in written) == sorted(
        [f"{t.__name__}.json" for t in MESSAGE_TYPES] + ["index.json"]
    )
    index = json.loads((tmp_path / "schemas" / "index.json").read_text())
    for type_name, file_name in index["types"].items():
        assert json.loads((tmp_path / "schemas" / file_name).read_text())["title"] == type_name
    for type_name in index["topics"].values():
        assert type_name in index["types"]


def test_cli_writes_valid_json_files(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], schema_only_cli: None
) -> None:
    assert cli.main(["schema", "--out", str(tmp_path)]) == 0
    files = sorted(tmp_path.glob("*.json"))
    assert len(files) == len(MESSAGE_TYPES) + 1
    documents = {path.name: json.loads(path.read_text()) for path in files}
    state = documents["RobotState.json"]["properties"]
    assert state["arm_joints"]["minItems"] == 1 and "maxItems" not in state["arm_joints"]
    assert state["joint_names"]["type"] == "array"  # no joint count fixed: the robot's names
    assert documents["index.json"]["topics"]["robot/state"] == "RobotState"
    assert sorted(capsys.readouterr().out.split()) == [str(path) for path in files]


def test_cli_prints_the_index_without_out(
    capsys: pytest.CaptureFixture[str], schema_only_cli: None
) -> None:
    assert cli.main(["schema"]) == 0
    assert json.loads(capsys.readouterr().out) == schema_index()
