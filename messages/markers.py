"""Fiducial markers seen by the vision tracker."""

from __future__ import annotations

from pydantic import Field

from messages.base import Message, NonNegative, UnitDualQuaternion
from messages.header import Header


class MarkerDetection(Message):
    """One marker: its id, its pose in the header's frame, and the fit's
    reprojection error in pixels."""

    id: int
    pose: UnitDualQuaternion
    reprojection_error: NonNegative


MAX_MARKERS = 1024
"""The most markers one image's detections may hold (the ArUco 4x4 dictionaries have 1000)."""


class MarkerDetections(Message):
    """Every marker found in one image (possibly none, at most ``MAX_MARKERS``)."""

    header: Header
    markers: tuple[MarkerDetection, ...] = Field(default=(), max_length=MAX_MARKERS)
