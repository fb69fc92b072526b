"""Standard output carries a command's result and nothing else.

While a command runs, file descriptor 1 and ``sys.stdout`` point at standard error, so whatever
a library prints there (HiGHS 1.16 prints a banner from its C++ constructor) reaches the
terminal as a log line, never the result. The result goes through ``emit``, which writes to the
original standard output.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import sys
from collections.abc import Iterator, Sequence
from typing import Any, TextIO

_result: TextIO | None = None


def table(rows: Sequence, headers: Sequence[str] | str = "keys", **style: Any) -> str:
    """Rows (dicts, with ``headers="keys"``, or sequences under ``headers``) as a plain text
    table, numbers right-aligned: the one table style of every command and benchmark
    (``tabulate``; ``style`` passes ``floatfmt`` and the like on)."""
    from tabulate import tabulate  # tens of ms of CPU: only a command that prints a table pays

    return tabulate(rows, headers=headers, tablefmt="plain", missingval="-", **style)


def json_text(value: Any, **style: Any) -> str:
    """``value`` as standard JSON (``style`` passes ``indent`` and the like to ``json.dumps``): a
    NaN or an infinity, such as the median of no steps, is written null."""
    return json.dumps(finite(value), allow_nan=False, **style)


def finite(value: Any) -> Any:
    """``value`` with every float that is not finite replaced by None, in lists, tuples and
    dicts at any depth."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, list | tuple):
        return [finite(v) for v in value]
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    return value


def emit(text: str) -> None:
    """Write one result line (JSON or a table) to the command's standard output."""
    stream = _result if _result is not None else sys.stdout
    stream.write(text + "\n")
    stream.flush()


@contextlib.contextmanager
def result_only_stdout() -> Iterator[None]:
    """Send fd 1 and ``sys.stdout`` to standard error; keep the original stdout for ``emit``.

    When ``sys.stdout`` is not file descriptor 1 (a caller captured it), results go there and
    the descriptors are left alone.
    """
    global _result
    if not _is_descriptor_1(sys.stdout):
        yield
        return
    sys.stdout.flush()
    saved = os.dup(1)
    previous_stdout = sys.stdout
    try:
        os.dup2(2, 1)
        _result = os.fdopen(os.dup(saved), "w", encoding="utf-8")
        sys.stdout = sys.stderr
        yield
    finally:
        sys.stdout = previous_stdout
        if _result is not None:
            _result.close()
            _result = None
        os.dup2(saved, 1)
        os.close(saved)


def _is_descriptor_1(stream: TextIO) -> bool:
    try:
        return stream.fileno() == 1
    except (AttributeError, OSError, ValueError):
        return False
