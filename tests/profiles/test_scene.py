"""The ``scene`` section of a profile (profiles/scene.py): markers, camera, refusals by field."""

from __future__ import annotations

from pathlib import Path

import cv2
import pytest
import yaml

from profiles.profile import ProfileError, load_profile
from profiles.scene import ARUCO_DICTIONARIES, BaseMarker, GoalMarker, Marker, Scene

REPO = Path(__file__).resolve().parents[2]
PUB = {"name": "pub", "module": "scripted_publisher", "role": "tool"}
SCENE = {
    "reference": {"id": 0, "size_m": 0.3},
    "base": {"id": 1, "size_m": 0.12, "height_m": 0.09, "offset": [-0.08, 0.0]},
    "goal": {"id": 2, "size_m": 0.15},
    "obstacles": {"ids": [3, 4], "size_m": 0.1, "height_m": 0.3},
}


def write(tmp_path: Path, scene: object) -> Path:
    path = tmp_path / "profile.yaml"
    path.write_text(yaml.safe_dump({"namespace": "sim", "components": [PUB], "scene": scene}))
    return path


def refusal(tmp_path: Path, scene: object) -> str:
    with pytest.raises(ProfileError) as error:
        load_profile(write(tmp_path, scene))
    message = str(error.value)
    assert message.startswith(f"{tmp_path / 'profile.yaml'}: invalid profile"), message
    return message


def test_the_sim_profile_has_its_scene() -> None:
    scene = load_profile(REPO / "deploy/sim.yaml").scene
    assert isinstance(scene, Scene)
    assert (scene.reference.id, scene.base.id, scene.goal.id) == (0, 1, 2)
    assert scene.obstacles.ids == (3,)
    assert scene.camera.position == (0.8, 0.15, 2.5)
    assert scene.dictionary_id == cv2.aruco.DICT_4X4_50


def test_a_profile_without_a_scene_has_none(tmp_path: Path) -> None:
    path = tmp_path / "profile.yaml"
    path.write_text(yaml.safe_dump({"namespace": "sim", "components": [PUB]}))
    assert load_profile(path).scene is None


def test_a_scene_gets_defaults_for_what_it_leaves_out(tmp_path: Path) -> None:
    minimal = {key: SCENE[key] for key in ("reference", "base", "goal")}
    scene = load_profile(write(tmp_path, minimal)).scene
    assert scene is not None
    assert scene.dictionary == "DICT_4X4_50" and scene.obstacles.ids == ()
    assert (scene.camera.width, scene.camera.height) == (640, 480)
    assert scene.goal.offset == (0.0,) * 6 and scene.reference_pose == (0.0, 0.0, 0.0)


def test_markers_maps_every_id_to_its_size_and_height(tmp_path: Path) -> None:
    scene = load_profile(write(tmp_path, SCENE)).scene
    assert scene is not None
    markers = scene.markers()
    assert sorted(markers) == [0, 1, 2, 3, 4]
    sizes = {i: (m.size_m, m.height_m) for i, m in markers.items()}
    assert sizes == {0: (0.3, 0.0), 1: (0.12, 0.09), 2: (0.15, 0.0), 3: (0.1, 0.3), 4: (0.1, 0.3)}
    assert isinstance(markers[1], BaseMarker) and markers[1].offset == (-0.08, 0.0)
    assert isinstance(markers[2], GoalMarker)
    assert all(isinstance(m, Marker) and m.id == i for i, m in markers.items())


def test_the_dictionary_id_is_opencvs() -> None:
    scene = Scene.model_validate(SCENE)
    assert scene.dictionary_id == cv2.aruco.DICT_4X4_50
    other = Scene.model_validate({**SCENE, "dictionary": "DICT_5X5_100"})
    assert other.dictionary_id == cv2.aruco.DICT_5X5_100 != cv2.aruco.DICT_4X4_50


def test_the_dictionaries_are_opencvs() -> None:
    """A profile is checked without OpenCV, against a table that is OpenCV's own."""
    opencv = {}
    for name in (n for n in dir(cv2.aruco) if n.startswith("DICT_")):
        dictionary_id = getattr(cv2.aruco, name)
        count = cv2.aruco.getPredefinedDictionary(dictionary_id).bytesList.shape[0]
        opencv[name] = (dictionary_id, count)
    assert opencv == ARUCO_DICTIONARIES


@pytest.mark.parametrize(
    ("change", "field", "expected"),
    [
        ({"obstacles": {"ids": [3, 3]}}, "scene.obstacles.ids[1]", "obstacles.ids[0]"),
        ({"obstacles": {"ids": [3, 1]}}, "scene.obstacles.ids[1]", "already base.id"),
        ({"obstacles": {"ids": [3, 50]}}, "scene.obstacles.ids[1]", "not in DICT_4X4_50"),
        ({"obstacles": {"ids": [-3]}}, "scene.obstacles.ids[0]", "(ids 0 to 49)"),
        ({"goal": {"id": 999, "size_m": 0.1}}, "scene.goal.id", "not in DICT_4X4_50"),
        ({"goal": {"id": 2, "size_m": -0.15}}, "scene.goal.size_m", "greater than 0"),
        ({"reference": {"id": 0, "size_m": 0.0}}, "scene.reference.size_m", "greater than 0"),
        (
            {"base": {"id": 1, "size_m": 0.1, "height_m": -1}},
            "scene.base.height_m",
            "greater than or equal to 0",
        ),
        ({"reference": {"id": -1, "size_m": 0.3}}, "scene.reference.id", "greater than or equal"),
        ({"colour": "red"}, "scene.colour", "Extra inputs are not permitted"),
        ({"camera": {"lens": "wide"}}, "scene.camera.lens", "Extra inputs are not permitted"),
        (
            {"goal": {"id": 2, "size_m": 0.1, "offset": [0, 0, 1]}},
            "scene.goal.offset[3]",
            "Field required",
        ),
        ({"camera": {"position": [0, 0, -2.5]}}, "scene.camera.position[2]", "greater than 0"),
    ],
)
def test_invalid_scenes_name_the_field(
    tmp_path: Path, change: dict[str, object], field: str, expected: str
) -> None:
    message = refusal(tmp_path, {**SCENE, **change})
    assert f"  {field}" in message and expected in message, message


def test_a_missing_marker_is_named(tmp_path: Path) -> None:
    scene = {key: SCENE[key] for key in ("reference", "goal")}
    assert "  scene.base: Field required" in refusal(tmp_path, scene)


def test_an_unknown_dictionary_is_refused(tmp_path: Path) -> None:
    message = refusal(tmp_path, {**SCENE, "dictionary": "DICT_9X9_7"})
    assert "scene.dictionary" in message
    assert "not an OpenCV ArUco dictionary: 'DICT_9X9_7'" in message


def test_an_unknown_dictionary_is_reported_as_field_colon_message(tmp_path: Path) -> None:
    """Like every other refusal: '  <field path>: <what was wrong>'."""
    message = refusal(tmp_path, {**SCENE, "dictionary": "DICT_9X9_7"})
    assert "  scene.dictionary: not an OpenCV ArUco dictionary" in message, message


def test_a_repeated_id_outside_the_obstacles_names_the_marker_that_repeats(tmp_path: Path) -> None:
    message = refusal(tmp_path, {**SCENE, "goal": {"id": 0, "size_m": 0.15}})
    assert "marker id 0 is already reference.id" in message
    assert "scene.obstacles" not in message, message
    assert "  scene.goal.id" in message, message


TABLE = {
    "name": "table",
    "normal": [0, 0, 1],
    "offset": 0.4,
    "footprint": [[0.5, -0.4], [1.1, -0.4], [1.1, 0.4], [0.5, 0.4]],
}
POLE = {"name": "pole", "x": 0.2, "y": -0.3, "radius": 0.05, "height": 0.6}


def test_a_scene_declares_planes_and_cylinders_for_the_arm(tmp_path: Path) -> None:
    """Read into the obstacles of wbc.geometry.obstacles3d, in F0; none by default."""
    scene = load_profile(
        write(
            tmp_path,
            {
                **SCENE,
                "arm_obstacles": {
                    "planes": [TABLE, {"normal": [-1, 0, 0], "offset": -2.0}],
                    "cylinders": [POLE],
                },
            },
        )
    ).scene
    table, wall, pole = scene.arm_obstacles.solids()
    assert (table.name, table.offset, len(table.footprint)) == ("table", 0.4, 4)
    assert (wall.name, wall.normal, wall.footprint) == ("plane", (-1.0, 0.0, 0.0), ())
    assert (pole.x, pole.y, pole.radius, pole.height) == (0.2, -0.3, 0.05, 0.6)
    assert load_profile(write(tmp_path, SCENE)).scene.arm_obstacles.solids() == ()


@pytest.mark.parametrize(
    ("planes", "cylinders", "field", "expected"),
    [
        (
            [{**TABLE, "normal": [0, 0, 2]}],
            [],
            "scene.arm_obstacles.planes[0].normal",
            "expected a unit vector",
        ),
        (
            [{**TABLE, "normal": [1, 0, 0]}],
            [],
            "scene.arm_obstacles.planes[0].footprint",
            "only a horizontal plane",
        ),
        (
            [{**TABLE, "footprint": [[0, 0], [2, 0], [1, 0.2], [2, 2], [0, 2]]}],
            [],
            "scene.arm_obstacles.planes[0].footprint",
            "expected a convex polygon",
        ),
        (
            [{**TABLE, "footprint": [[0, 0], [1, 0]]}],
            [],
            "scene.arm_obstacles.planes[0].footprint",
            "at least 3",
        ),
        ([{**TABLE, "offset": "high"}], [], "scene.arm_obstacles.planes[0].offset", "valid number"),
        ([{**TABLE, "colour": "oak"}], [], "scene.arm_obstacles.planes[0].colour", "Extra inputs"),
        (
            [],
            [{**POLE, "radius": 0.0}],
            "scene.arm_obstacles.cylinders[0].radius",
            "greater than 0",
        ),
        (
            [],
            [{**POLE, "height": -1.0}],
            "scene.arm_obstacles.cylinders[0].height",
            "greater than 0",
        ),
        ([], [{"x": 0.0, "radius": 0.1}], "scene.arm_obstacles.cylinders[0].y", "Field required"),
        (
            [],
            [{**POLE, "radius": 1e300}],
            "scene.arm_obstacles.cylinders[0].radius",
            "expected a number > 0 and <= 100 m, got 1e+300",
        ),
        (
            [],
            [POLE, {**POLE, "height": 1e300}],
            "scene.arm_obstacles.cylinders[1].height",
            "<= 100 m",
        ),
        ([], [{**POLE, "x": -1e300}], "scene.arm_obstacles.cylinders[0].x, y", "within +-100 m"),
        (
            [{**TABLE, "offset": 1e300}],
            [],
            "scene.arm_obstacles.planes[0].offset",
            "within +-100 m",
        ),
        (
            [{**TABLE, "footprint": [[0, 0], [1e300, 0], [0, 1]]}],
            [],
            "scene.arm_obstacles.planes[0].footprint",
            "within +-100 m",
        ),
    ],
)
def test_invalid_arm_obstacles_name_the_field(
    tmp_path: Path, planes: list, cylinders: list, field: str, expected: str
) -> None:
    message = refusal(
        tmp_path, {**SCENE, "arm_obstacles": {"planes": planes, "cylinders": cylinders}}
    )
    assert f"  {field}" in message and expected in message, message
