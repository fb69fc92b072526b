"""Each detected marker drawn on the camera image (scenes/marker_annotations.py), as the view
of a ``Viewer``: read with nothing but its own schema."""

from __future__ import annotations

from messages import topics
from messages.header import Header
from messages.markers import MarkerDetection, MarkerDetections
from scenes.foxglove_views import Viewer
from tests.scenes.views_read import (
    STAMP_NS,
    decode,
    pose_dq,
    vector,
)


def test_each_marker_is_its_outline_and_id_on_the_image() -> None:
    camera = Header(stamp_ns=STAMP_NS, frame="camera", seq=3, source="test")
    corners = ((100.5, 50.25), (140.0, 52.0), (138.0, 90.0), (99.0, 88.5))
    seen = (
        MarkerDetection(
            id=3, pose=pose_dq(0.0, (0.1, 0.2, 2.5)), reprojection_error=0.3, corners=corners
        ),
        MarkerDetection(
            id=7,
            pose=pose_dq(0.0, (0.4, 0.0, 2.4)),
            reprojection_error=0.5,
            corners=tuple((u + 200, v) for u, v in corners),
        ),
    )
    key = "sim/vision/markers"
    _, view = Viewer()(
        topics.VISION_MARKERS.name, key, MarkerDetections(header=camera, markers=seen)
    )
    assert view.channel(key)[0] == f"{key}/annotations"
    assert view.schema_name == "foxglove.ImageAnnotations"
    annotations = decode(view)
    assert len(annotations["points"]) == len(annotations["texts"]) == 2
    outline = annotations["points"][0]
    assert outline["type"] == 2  # LINE_LOOP
    assert [vector(p, "xy") for p in outline["points"]] == [list(c) for c in corners]
    assert outline["timestamp"] == {"seconds": STAMP_NS // 10**9, "nanos": STAMP_NS % 10**9}
    assert [t["text"] for t in annotations["texts"]] == ["id 3", "id 7"]
    # A frame without markers clears the last one's annotations.
    (empty,) = Viewer()(topics.VISION_MARKERS.name, key, MarkerDetections(header=camera))
    assert set(decode(empty)) == {"timestamp"}
