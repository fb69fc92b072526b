"""ROS 2 without ROS: rmw_zenoh's wire format (``ros2.wire``), the robot's URDF
(``ros2.urdf``) and recordings as ROS 2 bags (``ros2.bag``), for ROS 2 Jazzy."""
