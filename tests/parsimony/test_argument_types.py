"""A positive argument (``--rate``, ``--every``...) takes a finite number above 0, a count
(``--runs``) a whole number from 1, and each refuses anything else in argparse's one-line usage
error, saying what it expected."""

from __future__ import annotations

import argparse

import pytest

from parsimony.argument_types import count, positive, positive_seconds


def parser() -> argparse.ArgumentParser:
    made = argparse.ArgumentParser(prog="parsimony replay")
    made.add_argument("--rate", type=positive("times the recorded speed"), default=1.0)
    made.add_argument("--every", type=positive_seconds, default=1.0)
    made.add_argument("--runs", type=count("runs"), default=1)
    return made


def test_a_finite_number_above_zero_is_taken() -> None:
    args = parser().parse_args(["--rate", "2.5", "--every", "1e-3"])
    assert (args.rate, args.every) == (2.5, 0.001)
    assert positive_seconds(" 3 ") == 3.0


@pytest.mark.parametrize("text", ["0", "-1", "nan", "inf", "-inf"])
def test_zero_negative_and_non_finite_are_refused(text: str, capsys) -> None:
    with pytest.raises(SystemExit) as exited:
        parser().parse_args([f"--every={text}"])  # -inf is no option
    assert exited.value.code == 2
    error = capsys.readouterr().err.strip().splitlines()[-1]
    assert error == (
        f"parsimony replay: error: argument --every: "
        f"expected a finite number of seconds > 0, got {text!r}"
    )


def test_not_a_number_is_refused_saying_what_was_expected(capsys) -> None:
    with pytest.raises(SystemExit):
        parser().parse_args(["--rate", "fast"])
    error = capsys.readouterr().err.strip().splitlines()[-1]
    assert error.endswith("argument --rate: expected times the recorded speed, got 'fast'")


def test_a_count_is_a_whole_number_from_one(capsys) -> None:
    assert parser().parse_args(["--runs", "6"]).runs == 6
    for text, expected in (
        ("0", "expected at least 1 of runs, got '0'"),
        ("-2", "expected at least 1 of runs, got '-2'"),
        ("1.5", "expected a whole number of runs, got '1.5'"),
    ):
        with pytest.raises(SystemExit) as exited:
            parser().parse_args([f"--runs={text}"])
        assert exited.value.code == 2
        error = capsys.readouterr().err.strip().splitlines()[-1]
        assert error == f"parsimony replay: error: argument --runs: {expected}"
