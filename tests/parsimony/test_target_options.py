"""The options of the commands that talk to a running system: the profile from --profile or
$PARSIMONY_PROFILE, a clear line when there is none, and the exit codes (1: the system did not
answer or refused; 2: bad input or no router)."""

from __future__ import annotations

import pytest

from launch.query import NoRouter, QueryError
from parsimony.target_options import (
    EXIT_BAD_INPUT,
    EXIT_REFUSED,
    exit_code,
    fail,
    profile_and_target,
    target_options,
)
from profiles.profile import ProfileError


def test_the_profile_comes_from_the_option_else_the_environment(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setenv("PARSIMONY_PROFILE", "deploy/sim.yaml")
    parser = target_options()
    assert parser.parse_args([]).profile == "deploy/sim.yaml"
    assert parser.parse_args(["--profile", "deploy/ros2.yaml"]).profile == "deploy/ros2.yaml"
    args = parser.parse_args(["--timeout", "0.5", "--json"])
    assert args.timeout == 0.5 and args.json


def test_the_target_is_the_profiles_namespace_and_router(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("PARSIMONY_PROFILE", raising=False)
    profile, target = profile_and_target(
        target_options().parse_args(["--profile", "deploy/sim.yaml"])
    )
    assert target.namespace == profile.namespace == "sim"
    assert target.zenoh == profile.zenoh


def test_no_profile_at_all_says_how_to_give_one(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("PARSIMONY_PROFILE", raising=False)
    with pytest.raises(ProfileError, match=r"no profile: pass --profile or set PARSIMONY_PROFILE"):
        profile_and_target(target_options().parse_args([]))


def test_a_refusal_is_1_and_bad_input_or_no_router_is_2() -> None:
    assert (EXIT_REFUSED, EXIT_BAD_INPUT) == (1, 2)
    assert exit_code(QueryError("not answered")) == 1
    assert exit_code(NoRouter("cannot reach a router")) == 2
    assert exit_code(ProfileError("no such profile file")) == 2


def test_fail_says_the_error_in_one_line_on_stderr(capsys: pytest.CaptureFixture[str]) -> None:
    assert fail(NoRouter("cannot reach a router at tcp/127.0.0.1:1")) == 2
    out, err = capsys.readouterr()
    assert out == "" and err == "cannot reach a router at tcp/127.0.0.1:1\n"
