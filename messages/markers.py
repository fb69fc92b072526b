"""Fiducial markers seen by the vision tracker."""

from __future__ import annotations

from messages.base import Message, NonNegative, UnitDualQuaternion
from messages.header import Header


class MarkerDetection(Message):
    """One marker: its id, its pose in the header's frame, and the fit's
    reprojection error in pixels."""

    id: int
    pose: UnitDualQuaternion
    reprojection_error: NonNegative


class MarkerDetections(Message):
    """Every marker found in one image (possibly none)."""

    header: Header
    markers: tuple[MarkerDetection, ...] = ()
