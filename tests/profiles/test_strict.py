"""The profile's models refuse keys they do not know (a misspelt key is an error, not silently
ignored) and cannot be changed once loaded."""

from __future__ import annotations

import pydantic
import pytest

from profiles.strict import StrictModel


class Restart(StrictModel):
    max_restarts: int = 3
    backoff_s: float = 1.0


def test_known_keys_are_taken() -> None:
    assert Restart.model_validate({"max_restarts": 5}) == Restart(max_restarts=5, backoff_s=1.0)


def test_an_unknown_key_is_an_error_naming_it() -> None:
    with pytest.raises(pydantic.ValidationError) as refused:
        Restart.model_validate({"max_restart": 5})
    (error,) = refused.value.errors()
    assert error["loc"] == ("max_restart",) and error["type"] == "extra_forbidden"


def test_a_loaded_model_cannot_be_changed() -> None:
    policy = Restart()
    with pytest.raises(pydantic.ValidationError):
        policy.max_restarts = 10
    assert policy.max_restarts == 3
    assert hash(policy) == hash(Restart())  # frozen: usable as a key
