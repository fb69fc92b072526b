"""messages.joints: measured joints' names, positions and velocities line up."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from messages import JointStates
from tests.messages.message_examples import HEADER


def test_joint_states_must_line_up() -> None:
    with pytest.raises(ValidationError, match=r"lengths \(2, 2, 1\)"):
        JointStates(header=HEADER, names=("a", "b"), positions=(0, 0), velocities=(0,))
    with pytest.raises(ValidationError, match="not unique"):
        JointStates(header=HEADER, names=("a", "a"), positions=(0, 0), velocities=(0, 0))
