"""The `parsimony` command as a user runs it, a real process: every subcommand listed, and what a
library writes to file descriptor 1 kept out of a command's result (each command's own tests:
tests/parsimony/commands/test_<command>.py)."""

from __future__ import annotations

import json
import subprocess
import sys

from parsimony.cli import COMMANDS
from tests.parsimony.cli_process import run_cli


def test_help_lists_every_subcommand():
    result = run_cli("--help")
    assert result.returncode == 0
    for name in COMMANDS:
        assert name in result.stdout


def test_a_library_writing_to_file_descriptor_1_reaches_stderr():
    """What C code writes to fd 1 while a command runs is routed to stderr, not the result."""
    code = (
        "import os, sys\n"
        "from outputs.stdout import emit, result_only_stdout\n"
        "with result_only_stdout():\n"
        "    os.write(1, b'banner from C\\n')\n"
        "    print('a log line')\n"
        "    emit('{\"result\": 1}')\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout) == {"result": 1}
    assert "banner from C" in result.stderr and "a log line" in result.stderr
