"""Argument types the commands share (cheap to import: no command's module comes with them)."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable


def positive(what: str) -> Callable[[str], float]:
    """An argument type: a finite number > 0 of ``what`` (``nan``, ``inf`` and ``-1`` are
    refused, saying what was expected)."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}") from None
        if not math.isfinite(value) or value <= 0.0:
            raise argparse.ArgumentTypeError(
                f"expected a finite number of {what} > 0, got {text!r}"
            )
        return value

    parse.__name__ = what  # argparse names the type in its own messages
    return parse


positive_seconds = positive("seconds")
"""A duration in seconds."""


def count(what: str) -> Callable[[str], int]:
    """An argument type: a whole number >= 1 of ``what`` (``0``, ``-2`` and ``1.5`` are refused,
    saying what was expected)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"expected a whole number of {what}, got {text!r}"
            ) from None
        if value < 1:
            raise argparse.ArgumentTypeError(f"expected at least 1 of {what}, got {text!r}")
        return value

    parse.__name__ = what
    return parse
