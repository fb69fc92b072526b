"""messages.markers: the markers of one image, at most ``MAX_MARKERS``, their corners where an
image gave them."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from messages import IDENTITY_POSE, MarkerDetection, MarkerDetections
from messages.markers import MAX_MARKERS
from tests.messages.message_examples import HEADER


def test_one_image_holds_at_most_as_many_markers_as_a_4x4_dictionary_and_some() -> None:
    marker = MarkerDetection(id=0, pose=IDENTITY_POSE, reprojection_error=0.0)
    assert MAX_MARKERS == 1024 and MarkerDetections(header=HEADER).markers == ()
    assert len(MarkerDetections(header=HEADER, markers=(marker,) * MAX_MARKERS).markers) == 1024
    with pytest.raises(ValidationError, match="markers"):
        MarkerDetections(header=HEADER, markers=(marker,) * (MAX_MARKERS + 1))


def test_a_marker_has_four_corners_or_none() -> None:
    corners = ((10.0, 20.0), (30.0, 20.0), (30.0, 40.0), (10.0, 40.0))
    marker = MarkerDetection(id=7, pose=IDENTITY_POSE, reprojection_error=0.5, corners=corners)
    assert marker.corners == corners
    assert MarkerDetection(id=7, pose=IDENTITY_POSE, reprojection_error=0.5).corners is None
    with pytest.raises(ValidationError, match="corners"):
        MarkerDetection(id=7, pose=IDENTITY_POSE, reprojection_error=0.5, corners=corners[:3])
    with pytest.raises(ValidationError, match="reprojection_error"):
        MarkerDetection(id=7, pose=IDENTITY_POSE, reprojection_error=-0.1)
