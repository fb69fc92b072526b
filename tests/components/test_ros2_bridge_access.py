"""The ROS 2 bridge under a profile's access rules (``zenoh.access``): it is the Zenoh user
``ros2_bridge``, and its goals reach goal/request only where the profile names it among the
topic's writers (the router drops the others' puts)."""

from __future__ import annotations

import threading
import time
from pathlib import Path

import pytest
import yaml
import zenoh

from components.ros2_bridge import Ros2Bridge
from components.runtime import Node
from launch import query
from messages import topics
from profiles.deploy_files import ROBOT_FILE
from profiles.endpoints import free_port
from profiles.profile import load_profile
from tests.components.conftest import DEADLINE_S
from tests.ros2.pose_stamped import pose_stamped
from tests.ros2.rmw_keys import ATTACHMENT, DOMAIN, design_key

NAMESPACE = "rosacl"


def goals_on_request(tmp_path: Path, writers: list[str]) -> tuple[int, int]:
    """(goals the bridge passed on, goals that reached goal/request) for one ROS 2 goal, with
    ``writers`` the writers of goal/request."""
    (tmp_path / "credentials.txt").write_text("operator:op-secret\nros2_bridge:bridge-secret\n")
    data = {
        "namespace": NAMESPACE,
        "robot": str(ROBOT_FILE),
        "zenoh": {
            "mode": "client",
            "router": [f"tcp/127.0.0.1:{free_port()}"],
            "access": {"credentials": "credentials.txt", "writers": {"goal/request": writers}},
        },
        "components": [
            {
                "name": "ros2_bridge",
                "module": "ros2_bridge",
                "role": "tool",
                "params": {"domain_id": DOMAIN},
            }
        ],
    }
    path = tmp_path / "profile.yaml"
    path.write_text(yaml.safe_dump(data))
    profile = load_profile(path)
    arrived = threading.Event()
    declared = Ros2Bridge.params, Ros2Bridge.reads, Ros2Bridge.writes
    with (
        zenoh.open(profile.zenoh.router_config(NAMESPACE)),
        zenoh.open(profile.zenoh.client_config("operator")) as operator,
        Node(profile, "ros2_bridge", *declared) as node,
    ):
        component = Ros2Bridge(node)
        node.start(component.shutdown)
        operator.declare_subscriber(topics.GOAL_REQUEST.key(NAMESPACE), lambda _: arrived.set())
        ros = operator.declare_publisher(design_key("goal_pose", "geometry_msgs/msg/PoseStamped"))
        deadline = time.monotonic() + DEADLINE_S
        while not ros.matching_status.matching:
            assert time.monotonic() < deadline, "the bridge did not subscribe to /goal_pose"
            time.sleep(0.01)
        ros.put(pose_stamped("world", (1.0, 0.0, 0.5)), attachment=ATTACHMENT)
        while (passed := query.status_of(operator, NAMESPACE, "ros2_bridge").counters)[
            "goals_passed"
        ] < 1:
            assert time.monotonic() < deadline, f"the bridge passed nothing on: {passed}"
            time.sleep(0.01)
        # the status query's answer travels after the goal: the router has dealt with the put
        if writers == ["operator"]:
            query.status_of(operator, NAMESPACE, "ros2_bridge")
            return passed["goals_passed"], int(arrived.is_set())
        return passed["goals_passed"], int(arrived.wait(DEADLINE_S))


@pytest.mark.parametrize(
    ("writers", "reached"),
    [(["operator", "ros2_bridge"], 1), (["operator"], 0)],
    ids=["a writer", "not a writer"],
)
def test_the_bridges_goals_reach_the_supervisor_only_if_it_may_write(tmp_path, writers, reached):
    assert goals_on_request(tmp_path, writers) == (1, reached)
