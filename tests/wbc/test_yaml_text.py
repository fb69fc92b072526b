"""YAML text read fast (libyaml, where PyYAML has it) with PyYAML's safe constructor, and its
errors told as PyYAML tells them, at ``name:line:column``."""

from __future__ import annotations

import pytest
import yaml

from wbc.yaml_text import FAST_LOADER, error_place, parse_yaml


def pyyaml_error(text: str, name: str) -> yaml.YAMLError:
    """The error PyYAML's own safe loader raises on ``text`` read as ``name``."""
    loader = yaml.SafeLoader(text)
    loader.name = name
    try:
        loader.get_single_data()
    except yaml.YAMLError as error:
        return error
    finally:
        loader.dispose()
    raise AssertionError(f"PyYAML read {text!r}")


def test_the_fast_loader_is_libyamls_where_pyyaml_has_it() -> None:
    if yaml.__with_libyaml__:
        assert FAST_LOADER is yaml.CSafeLoader
    assert issubclass(FAST_LOADER, yaml.constructor.SafeConstructor)


def test_a_document_is_read_as_the_safe_loader_reads_it() -> None:
    text = "name: arm\njoints: [q1, q2]\nlimits: {low: -1.5, high: 1.5}\nservo: 0x1f\nok: yes\n"
    data = {
        "name": "arm",
        "joints": ["q1", "q2"],
        "limits": {"low": -1.5, "high": 1.5},
        "servo": 31,
        "ok": True,
    }
    assert parse_yaml(text, "robot.yaml") == data
    assert parse_yaml("", "empty.yaml") is None


@pytest.mark.parametrize(
    "text",
    [
        "a: 1\nb: [1, 2\n",  # an unclosed list
        "a: 1\n  b: 2\n",  # a bad indent
        "a: !!python/object:os.system {}\n",  # not safe
        "a: 1\n---\nb: 2\n",  # two documents
    ],
)
def test_an_error_is_pyyamls_own(text: str) -> None:
    with pytest.raises(yaml.YAMLError) as refused:
        parse_yaml(text, "profile.yaml")
    expected = pyyaml_error(text, "profile.yaml")
    assert type(refused.value) is type(expected)
    assert str(refused.value) == str(expected)


def test_an_error_is_placed_at_its_line_and_column() -> None:
    with pytest.raises(yaml.YAMLError) as refused:
        parse_yaml("a: 1\nb: [1, 2\n", "profile.yaml")
    assert error_place(refused.value, "profile.yaml") == "profile.yaml:3:1"  # at the end
    assert error_place(yaml.YAMLError("no mark"), "profile.yaml") == "profile.yaml"
