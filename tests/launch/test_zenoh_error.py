"""Zenoh's errors as one readable line (launch/zenoh_error.py)."""

from __future__ import annotations

import zenoh

from launch.zenoh_error import is_session_error, zenoh_error_text


def test_the_text_is_the_first_line_without_the_rust_source_location() -> None:
    error = zenoh.ZError(
        "Unable to connect to any of [Single(tcp/127.0.0.1:1)]!  at src/net/runtime.rs:412.\n"
        "caused by: refused"
    )
    assert zenoh_error_text(error) == "Unable to connect to any of [Single(tcp/127.0.0.1:1)]!"
    assert zenoh_error_text(zenoh.ZError("")) == "ZError"


def test_only_zenohs_own_errors_are_session_errors() -> None:
    assert is_session_error(zenoh.ZError("session closed"))
    assert not is_session_error(ValueError("no"))
