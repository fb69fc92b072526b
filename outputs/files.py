"""The files and directories a command writes: never one of its inputs, never an existing one
unless the user said ``--force``."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterable, Iterator
from pathlib import Path


def writable_output(output: Path, inputs: Iterable[Path], force: bool) -> str | None:
    """Why ``output`` may not be written (it is an input, or exists and ``force`` is not set),
    or None."""
    output = Path(output)
    for given in map(Path, inputs):
        both = given.exists() and output.exists()
        if given.resolve() == output.resolve() or (both and given.samefile(output)):
            return f"{output} is also an input; write the output elsewhere"
    if Path(output).exists() and not force:
        return f"{output} exists; give --force to replace it"
    return None


@contextlib.contextmanager
def written_whole(output: Path) -> Iterator[Path]:
    """A path to write ``output`` at: a hidden file beside it, renamed onto it when the block
    ends well and removed when it raises, so a failed command leaves no output, and a
    replaced one stays whole until the new one is."""
    output = Path(output)
    partial = output.with_name(f".{output.name}.partial")
    try:
        yield partial
    except BaseException:
        partial.unlink(missing_ok=True)
        raise
    os.replace(partial, output)
