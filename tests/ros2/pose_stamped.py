"""For tests: a goal as a ROS 2 tool sends it, a PoseStamped's CDR from rosbags' own serialiser."""

from __future__ import annotations

from tests.ros2.rmw_keys import store


def pose_stamped(frame: str, position, orientation=(1.0, 0.0, 0.0, 0.0)) -> bytes:
    """A ``geometry_msgs/msg/PoseStamped`` in ``frame`` at ``position`` with ``orientation``
    (w, x, y, z), stamped 0, as CDR."""
    types = (typestore := store()).types
    w, x, y, z = orientation
    message = types["geometry_msgs/msg/PoseStamped"](
        header=types["std_msgs/msg/Header"](
            stamp=types["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id=frame
        ),
        pose=types["geometry_msgs/msg/Pose"](
            position=types["geometry_msgs/msg/Point"](x=position[0], y=position[1], z=position[2]),
            orientation=types["geometry_msgs/msg/Quaternion"](x=x, y=y, z=z, w=w),
        ),
    )
    return bytes(typestore.serialize_cdr(message, "geometry_msgs/msg/PoseStamped"))
