"""The fiducial markers of a workspace and the ceiling camera that watches them (section 6.1.1).

Declared once in a profile's ``scene`` section and read by every component that needs them:
the simulator draws them, the vision tracker measures them, the state estimator gives them
their roles::

    F0  reference   fixed on the floor; the world frame of every estimate (eq. 6.2)
    F1  base        on the base's top plate, at ``offset`` (x, y) in the base frame
    F2  goal        the trash bin; the goal is x_d = x_2^0 x_d^2 (eq. 6.3), x_d^2 = ``goal.offset``
    F3  obstacles   one marker on top of each obstacle, a circle of ``radius`` around it

Every marker lies flat, its face up, ``height`` metres above the floor (the plane the tracker
intersects its ray with). Sizes are the black square's side, m.

``arm_obstacles`` declares what no marker shows: planes (a wall, a table top over its
footprint) and vertical cylinders (poles), in F0, that the robot's collision parts keep clear
of (``wbc.geometry.obstacles3d``, ``wbc.laws.constraints.arm_obstacles``)::

    arm_obstacles:
      planes:    [{name: table, normal: [0, 0, 1], offset: 0.4,
                   footprint: [[0.5, -0.4], [1.1, -0.4], [1.1, 0.4], [0.5, 0.4]]}]
      cylinders: [{name: pole, x: 0.2, y: -0.3, radius: 0.05, height: 0.6}]
"""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field, model_validator

from messages.obstacles import Solids

Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0.0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0.0, allow_inf_nan=False)]

ARUCO_DICTIONARIES: dict[str, tuple[int, int]] = {
    **{
        f"DICT_{bits}X{bits}_{count}": (4 * (bits - 4) + index, count)
        for bits in (4, 5, 6, 7)
        for index, count in enumerate((50, 100, 250, 1000))
    },
    "DICT_ARUCO_ORIGINAL": (16, 1024),
    **{
        f"DICT_{family}{code}": (dictionary_id, count)
        for family, name, dictionary_id, count in (
            ("APRILTAG_", "16h5", 17, 30),
            ("APRILTAG_", "25h9", 18, 35),
            ("APRILTAG_", "36h10", 19, 2320),
            ("APRILTAG_", "36h11", 20, 587),
            ("ARUCO_MIP_", "36h12", 21, 250),
        )
        for code in (name, name.upper())
    },
}
"""OpenCV's predefined ArUco dictionaries (``cv2.aruco.DICT_*``, both spellings it has): name
-> (id, how many markers). Written out so that loading a profile does not import OpenCV (some
30 ms of CPU in every process that loads one); tests/profiles/test_scene.py holds it to OpenCV's
own."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Marker(_Strict):
    """One marker: its ArUco ``id``, side ``size_m`` and the height of its face, m."""

    id: int = Field(ge=0)
    size_m: Positive
    height_m: NonNegative = 0.0


class BaseMarker(Marker):
    """F1: ``offset`` is the marker centre in the base frame, m (its x axis along the base's)."""

    offset: tuple[Finite, Finite] = (0.0, 0.0)


class GoalMarker(Marker):
    """F2: ``offset`` is x_d^2 of eq. 6.3 as (x, y, z, yaw, pitch, roll), m and rad, in F2."""

    offset: tuple[Finite, Finite, Finite, Finite, Finite, Finite] = (0.0,) * 6


class ObstacleMarkers(_Strict):
    """F3: the ids of the obstacle markers, their size and height, and each obstacle's radius."""

    ids: tuple[int, ...] = ()
    size_m: Positive = 0.15
    height_m: NonNegative = 0.0
    radius_m: Positive = 0.1

    def marker(self, marker_id: int) -> Marker:
        return Marker(id=marker_id, size_m=self.size_m, height_m=self.height_m)


class Camera(_Strict):
    """The ceiling camera: pinhole intrinsics (px) and frame rate. ``position`` (x, y, height)
    places the simulated one above the world; a real one is found through F0. ``latency_s``:
    the estimator uses a frame taken at t from its odometry of t + latency on (a real camera's
    frames, and the tracker's markers, come that late); a lockstep simulator waits for a
    frame's markers only then, so the tracker works while the loop runs on."""

    width: int = Field(default=640, gt=0)
    height: int = Field(default=480, gt=0)
    fx: Positive = 600.0
    fy: Positive = 600.0
    cx: Finite = 319.5
    cy: Finite = 239.5
    rate_hz: Positive = 30.0
    latency_s: Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)] = 0.0
    position: tuple[Finite, Finite, Positive] = (0.6, 0.15, 2.5)


class Scene(_Strict):
    """The markers and the camera of one workspace (see the module docstring)."""

    dictionary: str = "DICT_4X4_50"
    camera: Camera = Camera()
    reference: Marker
    reference_pose: tuple[Finite, Finite, Finite] = (0.0, 0.0, 0.0)
    """Where the simulator puts F0 on its floor: (x, y, yaw) in its own world frame."""
    base: BaseMarker
    goal: GoalMarker
    obstacles: ObstacleMarkers = ObstacleMarkers()
    arm_obstacles: Solids = Solids()
    """Planes and cylinders in 3-D, in F0 (see the module docstring)."""

    @model_validator(mode="after")
    def _known_dictionary(self) -> Scene:
        if self.dictionary not in ARUCO_DICTIONARIES:
            raise ValueError(
                f"dictionary: not an OpenCV ArUco dictionary: {self.dictionary!r} "
                "(e.g. 'DICT_4X4_50')"
            )
        return self

    @model_validator(mode="after")
    def _ids_unique(self) -> Scene:
        """Each marker id once and in the dictionary; the error names the marker (the later of
        two that share an id)."""
        size = ARUCO_DICTIONARIES[self.dictionary][1]
        fields = [
            ("reference.id", self.reference.id),
            ("base.id", self.base.id),
            ("goal.id", self.goal.id),
        ]
        fields += [
            (f"obstacles.ids[{i}]", marker_id) for i, marker_id in enumerate(self.obstacles.ids)
        ]
        seen: dict[int, str] = {}
        for field, marker_id in fields:
            if not 0 <= marker_id < size:
                raise ValueError(
                    f"{field}: marker id {marker_id} is not in {self.dictionary} "
                    f"(ids 0 to {size - 1})"
                )
            if marker_id in seen:
                raise ValueError(f"{field}: marker id {marker_id} is already {seen[marker_id]}")
            seen[marker_id] = field
        return self

    @model_validator(mode="after")
    def _cylinders_are_solids(self) -> Scene:
        """Each cylinder a solid of ``wbc.geometry.obstacles3d``, its sizes within the scene's
        extent (``EXTENT_M``), as each plane's message checks itself; the error names the field."""
        for index, cylinder in enumerate(self.arm_obstacles.cylinders):
            try:
                cylinder.solid()
            except ValueError as error:
                raise ValueError(f"arm_obstacles.cylinders[{index}].{error}") from None
        return self

    def solid_labels(self) -> tuple[str, ...]:
        """Each solid of ``arm_obstacles.solids()`` (planes first) by its name and field."""
        planes = self.arm_obstacles.planes
        return (
            *(f"{p.name!r} (scene.arm_obstacles.planes[{i}])" for i, p in enumerate(planes)),
            *(
                f"{c.name!r} (scene.arm_obstacles.cylinders[{i}])"
                for i, c in enumerate(self.arm_obstacles.cylinders)
            ),
        )

    @property
    def dictionary_id(self) -> int:
        """The OpenCV predefined dictionary id."""
        return ARUCO_DICTIONARIES[self.dictionary][0]

    def markers(self) -> dict[int, Marker]:
        """Every marker of the scene by id."""
        obstacles = (self.obstacles.marker(i) for i in self.obstacles.ids)
        return {m.id: m for m in (self.reference, self.base, self.goal, *obstacles)}
