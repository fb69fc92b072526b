"""messages.header: a header's stamp and counter fit an unsigned 64-bit word."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from messages import Header


def test_header_counts_are_non_negative() -> None:
    with pytest.raises(ValidationError, match="stamp_ns"):
        Header(stamp_ns=-1, frame="world", seq=0, source="test")
    with pytest.raises(ValidationError, match="seq"):
        Header(stamp_ns=0, frame="world", seq=2**64, source="test")
