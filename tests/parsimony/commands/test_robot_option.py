"""`--robot NAME|PATH`: a zoo robot by its name, a description's file as given, and a name the
zoo has not refused in one line that lists the zoo."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from parsimony.commands.robot_option import add_robot_option, robot_file
from profiles.deploy_files import DEPLOY


def test_a_zoo_name_is_its_description_in_deploy_robots() -> None:
    assert robot_file("youbot") == DEPLOY / "robots" / "youbot.yaml"


@pytest.mark.parametrize("text", ["mine.yaml", "mine.yml", "robots/mine", "/no/such/robot"])
def test_a_path_is_taken_as_given_even_when_absent(text: str) -> None:
    """A file named is the command's to open (and to refuse, naming it), not the zoo's."""
    assert robot_file(text) == Path(text)


def test_a_name_not_in_the_zoo_is_refused_with_the_zoos_names(
    capsys: pytest.CaptureFixture[str],
) -> None:
    parser = argparse.ArgumentParser(prog="parsimony bench")
    add_robot_option(parser)
    with pytest.raises(SystemExit) as exit:
        parser.parse_args(["--robot", "r2d2"])
    assert exit.value.code == 2
    [line] = [line for line in capsys.readouterr().err.splitlines() if "error:" in line]
    assert "no robot 'r2d2' in the zoo (" in line and "little_john" in line and "youbot" in line


def test_without_robot_the_default_is_little_johns_description() -> None:
    parser = argparse.ArgumentParser()
    add_robot_option(parser)
    assert parser.parse_args([]).robot == DEPLOY / "robots" / "little_john.yaml"
    add_robot_option(other := argparse.ArgumentParser(), default=None)
    assert other.parse_args([]).robot is None
