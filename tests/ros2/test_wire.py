"""rmw_zenoh's wire format against the golden vectors of its design document (rmw_zenoh_cpp
0.2.5, Jazzy) and ROS 2's type hash definition."""

import struct

import pytest

from ros2 import wire

STRING_HASH = "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"


def test_type_hash_of_std_msgs_string_is_ros2s():
    assert wire.type_hash("std_msgs/msg/String") == STRING_HASH


def test_data_keys_are_the_design_documents():
    assert wire.data_key("/chatter", "std_msgs/msg/String") == (
        f"0/chatter/std_msgs::msg::dds_::String_/{STRING_HASH}"
    )
    assert wire.data_key("chatter", "std_msgs/msg/String", namespace="/robot1") == (
        f"0/robot1/chatter/std_msgs::msg::dds_::String_/{STRING_HASH}"
    )
    assert wire.data_key("/joint_states", "sensor_msgs/msg/JointState", domain_id=7).startswith(
        "7/joint_states/sensor_msgs::msg::dds_::JointState_/RIHS01_"
    )


def test_liveliness_tokens_are_the_design_documents():
    listener = wire.Node("aac3178e146ba6f1fc6e6a4085e77f21", "listener", domain_id=2)
    assert listener.token() == "@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/0/NN/%/%/listener"
    assert listener.entity_token(10, "MS", "/chatter", "std_msgs/msg/String") == (
        "@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/10/MS/%/%/listener/%chatter/"
        f"std_msgs::msg::dds_::String_/{STRING_HASH}/::,10:,:,:,,"
    )
    talker = wire.Node("8b20917502ee955ac4476e0266340d5c", "talker", domain_id=2)
    assert talker.entity_token(10, "MP", "chatter", "std_msgs/msg/String", "::,7:,:,:,,") == (
        "@ros2_lv/2/8b20917502ee955ac4476e0266340d5c/0/10/MP/%/%/talker/%chatter/"
        f"std_msgs::msg::dds_::String_/{STRING_HASH}/::,7:,:,:,,"
    )


def test_namespace_and_enclave_are_mangled():
    node = wire.Node("ab", "bridge", namespace="/lab/robot1", enclave="/secure")
    assert node.token() == "@ros2_lv/0/ab/0/0/NN/%secure/%lab%robot1/bridge"
    assert "/%lab%robot1%odom/nav_msgs::msg::dds_::Odometry_/" in node.entity_token(
        3, "MP", "odom", "nav_msgs/msg/Odometry"
    )


def test_attachment_layout_round_trips():
    gid = bytes(range(16))
    data = wire.attachment(42, 1_700_000_000_123_456_789, gid)
    assert len(data) == 33
    assert data[:16] == struct.pack("<q", 42) + struct.pack("<q", 1_700_000_000_123_456_789)
    assert data[16] == 16 and data[17:] == gid
    assert wire.read_attachment(data) == (42, 1_700_000_000_123_456_789, gid)


@pytest.mark.parametrize(
    "call",
    [
        lambda: wire.attachment(1, 2, b"short"),
        lambda: wire.read_attachment(b"\x00" * 32),
        lambda: wire.read_attachment(b"\x00" * 16 + b"\x0f" + b"\x00" * 16),
        lambda: wire.type_hash("std_msgs/msg/NoSuchType"),
        lambda: wire.dds_type_name("String"),
        lambda: wire.data_key("/bad//name", "std_msgs/msg/String"),
        lambda: wire.Node("ab", "n").entity_token(1, "XX", "/t", "std_msgs/msg/String"),
    ],
)
def test_what_the_format_cannot_carry_is_refused(call):
    with pytest.raises(wire.WireError):
        call()
