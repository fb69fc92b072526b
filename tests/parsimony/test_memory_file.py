"""A file in memory that a child process reads at a path: the child reads the whole text (from
its start, wherever the writer left off) and nothing is left on disk once it is closed."""

from __future__ import annotations

import os
import subprocess

from parsimony.memory_file import memory_file

TEXT = "namespace: lab\ncomponents: []\n# é, a character of two bytes\n"


def test_a_child_that_inherits_the_descriptor_reads_the_text_at_the_path() -> None:
    descriptor, path = memory_file("record.yaml", TEXT)
    try:
        assert path.read_text() == TEXT  # this process reads it there too, from the start
        child = subprocess.run(
            ["cat", str(path)], pass_fds=(descriptor,), capture_output=True, check=True
        )
        assert child.stdout.decode() == TEXT
    finally:
        os.close(descriptor)
    assert not path.exists()  # gone with its descriptor: nothing left behind


def test_each_file_is_its_own() -> None:
    first, first_path = memory_file("a.yaml", "a: 1\n")
    second, second_path = memory_file("a.yaml", "b: 2\n")
    try:
        assert first_path != second_path
        assert (first_path.read_text(), second_path.read_text()) == ("a: 1\n", "b: 2\n")
    finally:
        os.close(first)
        os.close(second)
