"""Fiducial markers seen by the vision tracker."""

from __future__ import annotations

from pydantic import Field

from messages.base import Finite, Message, NonNegative, UnitDualQuaternion
from messages.header import Header

ImagePoint = tuple[Finite, Finite]
"""A point of an image (u, v), px, from its top-left corner."""


class MarkerDetection(Message):
    """One marker: its id, its pose in the header's frame, and the fit's
    reprojection error in pixels. ``corners`` are its four corners in the image it was found
    in (top-left, top-right, bottom-right, bottom-left of the marker, px), or ``None`` where
    the markers are not an image's (placed in the world frame, or recorded before corners were
    sent)."""

    id: int
    pose: UnitDualQuaternion
    reprojection_error: NonNegative
    corners: tuple[ImagePoint, ImagePoint, ImagePoint, ImagePoint] | None = None


MAX_MARKERS = 1024
"""The most markers one image's detections may hold (the ArUco 4x4 dictionaries have 1000)."""


class MarkerDetections(Message):
    """Every marker found in one image (possibly none, at most ``MAX_MARKERS``)."""

    header: Header
    markers: tuple[MarkerDetection, ...] = Field(default=(), max_length=MAX_MARKERS)
