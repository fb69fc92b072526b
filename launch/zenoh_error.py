"""Zenoh's errors as one readable line: the message without the Rust source location."""

from __future__ import annotations

import re

import zenoh

_SOURCE_LOCATION = re.compile(r"\s+at\s+\S+\.rs:\d+\.?")


def zenoh_error_text(error: BaseException) -> str:
    """``Unable to connect to any of [Single(tcp/127.0.0.1:1)]!`` from a ``zenoh.ZError``."""
    lines = [line.strip() for line in str(error).splitlines() if line.strip()]
    return _SOURCE_LOCATION.sub("", lines[0] if lines else type(error).__name__).strip()


def is_session_error(error: BaseException) -> bool:
    """Whether ``error`` is Zenoh's: a ``zenoh.ZError`` (a closed session), or a panic in its
    Rust code (pyo3's ``PanicException``, a ``BaseException`` whose class exists only once a
    panic was raised), after which the session may answer nothing again."""
    return isinstance(error, zenoh.ZError) or type(error).__name__ == "PanicException"
