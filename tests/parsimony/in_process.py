"""`parsimony ARGV` run by its entry point in the test's process, for the tests of what it refuses
before it runs anything, of commands that only read and write files, and of the short questions
and messages a command puts to a running system: the same parser, checks and output as the
command, without a Python start (a test of the process itself, its signals or its file
descriptors, runs one: tests/processes.py)."""

from __future__ import annotations

import contextlib
import io
import subprocess

import pytest

from parsimony.cli import main


def run_in_process(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    """The exit status of `parsimony ARGV` (argparse exits by itself), its stdout and its stderr;
    an exception it let out fails the test, as a traceback would."""
    code = exit_status(argv)
    out, err = capsys.readouterr()
    return code, out, err


def completed(*argv: str) -> subprocess.CompletedProcess[str]:
    """`parsimony ARGV` run as ``run_in_process`` runs it, its stdout and stderr caught in
    memory, as a process of its own gives them back (for helpers that have no ``capsys``)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = exit_status(list(argv))
    return subprocess.CompletedProcess(["parsimony", *argv], code, out.getvalue(), err.getvalue())


def exit_status(argv: list[str]) -> int:
    try:
        return main(argv)
    except SystemExit as exit:
        return int(exit.code or 0)
