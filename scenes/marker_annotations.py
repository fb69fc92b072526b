"""Each detected marker drawn on the camera image: ``foxglove.ImageAnnotations`` of a
``MarkerDetections``, stamped with the frame's stamp (the tracker's markers carry it), so
Foxglove's Image panel lays them on the frame they were found in.

A marker is the closed outline of its four corners (``MarkerDetection.corners``, px, as the
tracker found them), a dot on its first corner (top-left: the outline says which way it
turns), and its id beside it. A frame with no marker gives an empty set of its stamp, which
clears the last frame's."""

from __future__ import annotations

from foxglove import messages as fox

from messages.markers import MarkerDetections
from scenes.foxglove_frames import timestamp

OUTLINE_COLOR = fox.Color(r=0.1, g=0.9, b=0.2, a=1.0)
TEXT_COLOR = fox.Color(r=1.0, g=1.0, b=1.0, a=1.0)
TEXT_BACKGROUND = fox.Color(r=0.0, g=0.0, b=0.0, a=0.6)
OUTLINE_PX = 2.0
FIRST_CORNER_PX = 6.0
FONT_PX = 14.0


def marker_annotations(detections: MarkerDetections) -> fox.ImageAnnotations:
    """The outline, first corner and id of every marker that carries its corners."""
    stamp = timestamp(detections.header.stamp_ns)
    outlines, corners, labels = [], [], []
    for marker in detections.markers:
        if marker.corners is None:
            continue
        points = [fox.Point2(x=u, y=v) for u, v in marker.corners]
        outlines.append(
            fox.PointsAnnotation(
                timestamp=stamp,
                type=fox.PointsAnnotationType.LineLoop,
                points=points,
                outline_color=OUTLINE_COLOR,
                thickness=OUTLINE_PX,
            )
        )
        corners.append(
            fox.CircleAnnotation(
                timestamp=stamp,
                position=points[0],
                diameter=FIRST_CORNER_PX,
                thickness=OUTLINE_PX,
                outline_color=OUTLINE_COLOR,
                fill_color=OUTLINE_COLOR,
            )
        )
        labels.append(
            fox.TextAnnotation(
                timestamp=stamp,
                position=points[0],
                text=f"id {marker.id}",
                font_size=FONT_PX,
                text_color=TEXT_COLOR,
                background_color=TEXT_BACKGROUND,
            )
        )
    return fox.ImageAnnotations(timestamp=stamp, circles=corners, points=outlines, texts=labels)
