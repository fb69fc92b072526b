"""The ROS 2 messages the bridge (``components.ros2_bridge``) makes besides the state's
(``ros2.state_messages``): the ceiling camera as sensor_msgs/CompressedImage and CameraInfo,
its place on /tf_static, the goal's frame on /tf, /robot_description (std_msgs/String), /clock
on simulated time, and the controller's, the supervisor's and the bridge's own status as
diagnostic_msgs/DiagnosticArray."""

from __future__ import annotations

import numpy as np

from messages.camera import CameraFrame
from messages.diagnostics import ControllerDiagnostics
from messages.supervisor import SupervisorStatus
from ros2.state_messages import WORLD, header, transform_stamped
from ros2.urdf import matrix
from ros2.wire import typestore

CAMERA_FRAME = "ceiling_camera"
GOAL_FRAME = "goal"
COMPRESSED_IMAGE = ("/camera/image/compressed", "sensor_msgs/msg/CompressedImage")
CAMERA_INFO = ("/camera/camera_info", "sensor_msgs/msg/CameraInfo")
TF_STATIC = ("/tf_static", "tf2_msgs/msg/TFMessage")
ROBOT_DESCRIPTION = ("/robot_description", "std_msgs/msg/String")
DIAGNOSTICS = ("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray")
CLOCK = ("/clock", "rosgraph_msgs/msg/Clock")
GOAL_POSE = ("/goal_pose", "geometry_msgs/msg/PoseStamped")
"""The goal a ROS 2 node gives the end effector (rviz2's goal tool publishes here)."""
DIAGNOSTIC_LEVEL = {"ok": 0, "warn": 1, "error": 2}
SUPERVISOR_ERRORS = ("refused", "aborted", "unreachable")
"""The supervisor's phases said at level ERROR on /diagnostics."""


def _types():
    return typestore().types


def string(text: str):
    """std_msgs/String of ``text``."""
    return _types()["std_msgs/msg/String"](data=text)


def clock(stamp_ns: int):
    """rosgraph_msgs/Clock at ``stamp_ns``."""
    return _types()["rosgraph_msgs/msg/Clock"](clock=header(stamp_ns, "").stamp)


def static_transforms(camera_pose: np.ndarray | None, stamp_ns: int):
    """tf2_msgs/TFMessage of what does not move: the ceiling camera in the world (a unit dual
    quaternion; None: no camera)."""
    transforms = []
    if camera_pose is not None:
        transforms.append(transform_stamped(stamp_ns, WORLD, CAMERA_FRAME, matrix(camera_pose)))
    return _types()["tf2_msgs/msg/TFMessage"](transforms=transforms)


def compressed_image(frame: CameraFrame, jpeg_data: bytes):
    """sensor_msgs/CompressedImage of a frame whose JPEG file is ``jpeg_data``."""
    return _types()["sensor_msgs/msg/CompressedImage"](
        header=header(frame.header.stamp_ns, CAMERA_FRAME),
        format="jpeg",
        data=np.frombuffer(jpeg_data, dtype=np.uint8),
    )


def camera_info(frame: CameraFrame):
    """sensor_msgs/CameraInfo of a frame's intrinsics (plumb_bob, OpenCV's five coefficients)."""
    types, c = _types(), frame.intrinsics
    k = [c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0]
    p = [c.fx, 0.0, c.cx, 0.0, 0.0, c.fy, c.cy, 0.0, 0.0, 0.0, 1.0, 0.0]
    d = (list(c.distortion) + [0.0] * 5)[: max(5, len(c.distortion))]
    roi = types["sensor_msgs/msg/RegionOfInterest"](
        x_offset=0, y_offset=0, height=0, width=0, do_rectify=False
    )
    return types["sensor_msgs/msg/CameraInfo"](
        header=header(frame.header.stamp_ns, CAMERA_FRAME),
        height=frame.height,
        width=frame.width,
        distortion_model="plumb_bob",
        d=np.array(d, dtype=np.float64),
        k=np.array(k, dtype=np.float64),
        r=np.eye(3).reshape(9),
        p=np.array(p, dtype=np.float64),
        binning_x=0,
        binning_y=0,
        roi=roi,
    )


def _status(name: str, level: int, message: str, values: dict[str, object]):
    types = _types()
    return types["diagnostic_msgs/msg/DiagnosticStatus"](
        level=level,
        name=name,
        message=message,
        hardware_id="parsimony",
        values=[
            types["diagnostic_msgs/msg/KeyValue"](key=key, value=str(value))
            for key, value in values.items()
            if value is not None
        ],
    )


def controller_status(diagnostics: ControllerDiagnostics):
    """The controller's last step as a DiagnosticStatus: OK when it solved, else WARN."""
    level = 0 if diagnostics.status in ("ok", "optimal", "solved") else 1
    values = {
        "law": diagnostics.law,
        "status": diagnostics.status,
        "error_norm": diagnostics.error_norm,
        "nonzero": diagnostics.nonzero,
        "solve_time_us": diagnostics.solve_time_us,
    }
    message = diagnostics.status + (f": {diagnostics.reason}" if diagnostics.reason else "")
    return _status("parsimony/controller", level, message, values)


def supervisor_status(status: SupervisorStatus):
    """The supervisor's phase as a DiagnosticStatus: ERROR for a goal refused, aborted or
    unreachable (the message says why), WARN with a warning, else OK."""
    level = 2 if status.phase in SUPERVISOR_ERRORS else (1 if status.warning else 0)
    message = status.phase + (f": {status.reason}" if status.reason else "")
    values = {
        "phase": status.phase,
        "state": status.state,
        "error_norm": status.error_norm,
        "refusals": status.refusals,
        "last_refusal": status.last_refusal,
        "warning": status.warning,
    }
    return _status("parsimony/supervisor", level, message, values)


def bridge_status(counters: dict[str, int], last_refusal: str):
    """The bridge's refusals of ROS 2 input: WARN once any, the latest's reason its message."""
    refused = {key: value for key, value in counters.items() if key.startswith("refused.")}
    level = 1 if any(refused.values()) else 0
    return _status("parsimony/ros2_bridge", level, last_refusal or "ok", refused)


def diagnostic_array(stamp_ns: int, statuses: list):
    """diagnostic_msgs/DiagnosticArray of ``statuses``."""
    return _types()["diagnostic_msgs/msg/DiagnosticArray"](
        header=header(stamp_ns, ""), status=statuses
    )
