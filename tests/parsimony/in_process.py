"""`parsimony ARGV` run by its entry point in the test's process, for the tests of what it refuses
before it runs anything and of commands that only read and write files: the same parser and
checks as the command, without a Python start."""

from __future__ import annotations

import pytest

from parsimony.cli import main


def run_in_process(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    """The exit status of `parsimony ARGV` (argparse exits by itself), its stdout and its stderr;
    an exception it let out fails the test, as a traceback would."""
    try:
        code = main(argv)
    except SystemExit as exit:
        code = int(exit.code or 0)
    out, err = capsys.readouterr()
    return code, out, err
