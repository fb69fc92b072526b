"""A positive argument (``--rate``, ``--every``...) takes a finite number above 0 and refuses
anything else in argparse's one-line usage error, saying what it expected."""

from __future__ import annotations

import argparse

import pytest

from parsimony.argument_types import positive, positive_seconds


def parser() -> argparse.ArgumentParser:
    made = argparse.ArgumentParser(prog="parsimony replay")
    made.add_argument("--rate", type=positive("times the recorded speed"), default=1.0)
    made.add_argument("--every", type=positive_seconds, default=1.0)
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
