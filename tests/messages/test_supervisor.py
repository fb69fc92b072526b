"""messages.supervisor: the phases a supervisor status may name, and the longest way it
carries."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from messages.supervisor import MAX_WAY, PHASES, SupervisorStatus
from tests.messages.message_examples import HEADER


def _status(**fields: object) -> SupervisorStatus:
    return SupervisorStatus(header=HEADER, candidate=0, plans=0, replans=0, stalls=0, **fields)


def test_a_status_names_one_of_the_supervisors_phases() -> None:
    assert set(PHASES) == {
        "idle",
        "direct",
        "refused",
        "aborted",
        "planning",
        "drive",
        "turn",
        "approach",
        "align",
        "pose",
        "reached",
        "unreachable",
    }
    for phase in PHASES:
        assert _status(phase=phase).phase == phase
    with pytest.raises(ValidationError, match="phase"):
        _status(phase="parked")


def test_a_way_holds_eight_corners_a_disc_of_the_most_obstacles_and_three_points() -> None:
    assert MAX_WAY == 8 * 256 + 3
    assert len(_status(phase="drive", way=((0.0, 0.0),) * MAX_WAY).way) == MAX_WAY
    with pytest.raises(ValidationError, match="way"):
        _status(phase="drive", way=((0.0, 0.0),) * (MAX_WAY + 1))
