"""`parsimony export SESSION --ros2 -o DIR`: a recorded session as a ROS 2 bag, read back by
rosbags' own reader message for message."""

import json

import numpy as np
import pytest
from mcap.reader import make_reader
from rosbags.rosbag2 import Reader

from messages.camera import CameraFrame, CameraIntrinsics
from messages.diagnostics import ControllerDiagnostics
from messages.header import Header
from messages.state import RobotState
from messages.supervisor import SupervisorStatus
from messages.topics import CAMERA_IMAGE, CONTROL_DIAGNOSTICS, ROBOT_STATE, SUPERVISOR_STATUS
from profiles.deploy_files import ROBOT_FILE
from record.session_file import SessionWriter
from ros2.bag import LATCHED_QOS, check_joints
from ros2.urdf import ROOT, joints, link_name, matrix, planar, urdf
from ros2.wire import typestore
from tests.parsimony.in_process import run_in_process
from tests.robot_states import state_at
from vision.images import jpeg
from wbc.robot import BASE_DOF, MobileManipulator

ROBOT = MobileManipulator.from_yaml(ROBOT_FILE)
START_NS, DT_NS, STEPS = 1_700_000_000_000_000_000, 20_000_000, 25


def configurations() -> np.ndarray:
    """A base driving forward while turning and the arm's joints sweeping."""
    t = np.arange(STEPS) * DT_NS * 1e-9
    q = np.zeros((STEPS, ROBOT.dof))
    q[:, 2] = 0.5 * t
    q[:, 0] = np.cumsum(0.2 * np.cos(q[:, 2])) * DT_NS * 1e-9
    q[:, 1] = np.cumsum(0.2 * np.sin(q[:, 2])) * DT_NS * 1e-9
    q[:, BASE_DOF:] = 0.3 * np.sin(t[:, None] + np.arange(ROBOT.arm_dof))
    return q


def header(seq: int, source: str = "test") -> Header:
    return Header(stamp_ns=START_NS + seq * DT_NS, frame="world", seq=seq, source=source)


def state(seq: int, q: np.ndarray, valid: bool = True) -> RobotState:
    return state_at(ROBOT, q, header(seq), valid)


INTRINSICS = CameraIntrinsics(fx=200.0, fy=210.0, cx=32.0, cy=24.0, distortion=(0.1, -0.02))
JPEG = jpeg(np.full((48, 64), 128, np.uint8), 80)
FRAMES = [
    CameraFrame(
        header=header(s, "camera"), encoding=e, width=64, height=48, data=d, intrinsics=INTRINSICS
    )
    for s, e, d in ((3, "jpeg", JPEG), (5, "mono8", bytes(64 * 48)), (7, "jpeg", JPEG))
]
"""Two JPEG frames and a raw one, which the bag leaves out."""
CONTROLLER = [
    ControllerDiagnostics(
        header=header(s, "controller"),
        law="lp",
        status=status,
        reason=reason,
        nonzero=3,
        practical_nonzero=3,
        solve_time_us=120.0,
        error_norm=0.5,
    )
    for s, status, reason in ((2, "optimal", ""), (6, "infeasible", "joint limits"))
]
SUPERVISOR = SupervisorStatus(
    header=header(4, "supervisor"),
    phase="refused",
    candidate=0,
    plans=0,
    replans=0,
    stalls=0,
    reason="out of reach",
    refusals=1,
)


@pytest.fixture(scope="module")
def session(tmp_path_factory) -> tuple:
    path = tmp_path_factory.mktemp("session") / "run.mcap"
    qs = configurations()
    with SessionWriter(path) as writer:
        writer.write(ROBOT_STATE.key("far"), state(0, qs[0], valid=False))  # before a fix
        for seq, q in enumerate(qs):
            writer.write(ROBOT_STATE.key("far"), state(seq + 1, q))
        for frame in FRAMES:
            writer.write(CAMERA_IMAGE.key("far"), frame)
        for diagnostics in CONTROLLER:
            writer.write(CONTROL_DIAGNOSTICS.key("far"), diagnostics)
        writer.write(SUPERVISOR_STATUS.key("far"), SUPERVISOR)
    return path, qs


def test_bag_read_back_message_for_message(session, tmp_path, capsys):
    path, qs = session
    bag = tmp_path / "bag"
    code, out, err = run_in_process(
        ["export", str(path), "--ros2", "-o", str(bag), "--json"], capsys
    )
    assert code == 0, err
    result = json.loads(out)
    assert result["topics"] == {
        "/joint_states": STEPS,
        "/tf": STEPS,
        "/odom": STEPS,
        "/robot_description": 1,
        "/camera/image/compressed": 2,
        "/camera/camera_info": 2,
        "/diagnostics": 3,
    }
    assert result["frames_not_jpeg_left_out"] == 1 and "1 camera frames not JPEG" in err
    assert result["invalid_states_left_out"] == 1 and "1 states without a fix" in err
    assert result["start_ns"] == START_NS + DT_NS
    assert result["duration_s"] == pytest.approx((STEPS - 1) * DT_NS * 1e-9)
    assert (bag / "metadata.yaml").is_file() and result["size_bytes"] > 0
    (storage,) = bag.glob("*.mcap")
    with storage.open("rb") as stream:
        reader = make_reader(stream)
        assert reader.get_header().profile == "ros2"
        schemas = reader.get_summary().schemas.values()
        assert {s.encoding for s in schemas} == {"ros2msg"}
    store, tree = typestore(), joints(ROBOT)
    read: dict[str, list] = {}
    with Reader(bag) as reader:
        assert reader.duration == (STEPS - 1) * DT_NS + 1
        for connection in reader.connections:
            assert connection.msgdef.format.name == "MSG"  # ros2msg schemas
            assert connection.digest == store.hash_rihs01(connection.msgtype)
        for connection, stamp, data in reader.messages():
            message = store.deserialize_cdr(data, connection.msgtype)
            read.setdefault(connection.topic, []).append((stamp, message))
    for seq, q in enumerate(qs):
        stamp = START_NS + (seq + 1) * DT_NS
        (at, joint_state), (_, tf), (_, odom) = (
            read[t][seq] for t in ("/joint_states", "/tf", "/odom")
        )
        assert (
            at == stamp
            and joint_state.header.stamp.sec * 10**9 + joint_state.header.stamp.nanosec == stamp
        )
        assert joint_state.name == list(ROBOT.joint_names)
        np.testing.assert_array_equal(joint_state.position, q[BASE_DOF:])
        poses = {ROOT: planar(*q[:BASE_DOF])}
        for transform in tf.transforms:
            t, r = transform.transform.translation, transform.transform.rotation
            local = matrix(np.concatenate(([r.w, r.x, r.y, r.z], np.zeros(4))))
            local[:3, 3] = (t.x, t.y, t.z)
            parent = transform.header.frame_id
            poses[transform.child_frame_id] = local if parent == "world" else poses[parent] @ local
        assert len(tf.transforms) == len(tree) + 1
        for i, frame in enumerate(ROBOT.frames(q)):
            np.testing.assert_allclose(poses[link_name(i)], matrix(frame), atol=1e-9)
        position = odom.pose.pose.position
        assert (position.x, position.y) == (q[0], q[1]) and odom.child_frame_id == ROOT
        if seq:
            assert odom.twist.twist.angular.z == pytest.approx(0.5, rel=1e-6)
            assert odom.twist.twist.linear.x == pytest.approx(0.2, rel=1e-2)


def test_the_bridges_other_topics_read_back(session, tmp_path, capsys):
    """/robot_description (latched in the metadata), the JPEG frames with their intrinsics,
    and /diagnostics with the newest controller and supervisor statuses, as the bridge says."""
    path, _ = session
    bag = tmp_path / "bag"
    code, _, err = run_in_process(["export", str(path), "--ros2", "-o", str(bag)], capsys)
    assert code == 0, err
    store = typestore()
    read: dict[str, list] = {}
    with Reader(bag) as reader:
        qos = {c.topic: c.ext.offered_qos_profiles for c in reader.connections}
        for connection, stamp, data in reader.messages():
            message = store.deserialize_cdr(data, connection.msgtype)
            read.setdefault(connection.topic, []).append((stamp, message))
    assert qos["/robot_description"] == [LATCHED_QOS] and qos["/joint_states"] == []
    assert "durability: transient_local" in (bag / "metadata.yaml").read_text()
    ((at, description),) = read["/robot_description"]
    assert at == START_NS + DT_NS and description.data == urdf(ROBOT)
    jpegs = [f for f in FRAMES if f.encoding == "jpeg"]
    for frame, (at, image), (_, info) in zip(
        jpegs, read["/camera/image/compressed"], read["/camera/camera_info"], strict=True
    ):
        assert at == frame.header.stamp_ns and image.format == "jpeg"
        assert bytes(image.data) == JPEG and image.header.frame_id == "ceiling_camera"
        assert (info.width, info.height) == (64, 48) and info.distortion_model == "plumb_bob"
        assert list(info.k) == [200.0, 0.0, 32.0, 0.0, 210.0, 24.0, 0.0, 0.0, 1.0]
        assert list(info.d) == [0.1, -0.02, 0.0, 0.0, 0.0]
    said = [
        (at, [(s.name, s.level, s.message) for s in array.status])
        for at, array in read["/diagnostics"]
    ]
    controller, supervisor = "parsimony/controller", "parsimony/supervisor"
    assert said == [
        (START_NS + 2 * DT_NS, [(controller, 0, "optimal")]),
        (
            START_NS + 4 * DT_NS,
            [(controller, 0, "optimal"), (supervisor, 2, "refused: out of reach")],
        ),
        (
            START_NS + 6 * DT_NS,
            [(controller, 1, "infeasible: joint limits"), (supervisor, 2, "refused: out of reach")],
        ),
    ]


def test_a_wrong_robot_or_an_existing_directory_is_one_line(session, tmp_path, capsys):
    path, _ = session
    bag = tmp_path / "bag"
    code, _, err = run_in_process(
        ["export", str(path), "--ros2", "-o", str(bag), "--robot", "ur5e_fixed"], capsys
    )
    assert code == 2 and "arm joints" in err and "Traceback" not in err
    assert not bag.exists()
    bag.mkdir()
    code, _, err = run_in_process(["export", str(path), "--ros2", "-o", str(bag)], capsys)
    assert code == 2 and "exists" in err
    code, _, err = run_in_process(
        ["export", str(tmp_path / "none.mcap"), "--ros2", "-o", str(tmp_path / "b")], capsys
    )
    assert code == 2 and err.startswith("export:") and len(err.strip().splitlines()) == 1


def test_the_urdf_the_bags_frames_come_from(tmp_path, capsys):
    out = tmp_path / "robot.urdf"
    code, printed, err = run_in_process(
        ["export", "--urdf", "--robot", "youbot", "-o", str(out)], capsys
    )
    assert code == 0, err
    assert printed == f"{out}: {out.stat().st_size} bytes\n"
    assert out.read_text() == urdf(MobileManipulator.from_yaml("deploy/robots/youbot.yaml"))
    code, _, err = run_in_process(["export", "x.mcap", "--urdf", "-o", str(tmp_path / "u")], capsys)
    assert code == 2 and "no SESSION" in err


def test_a_state_naming_other_joints_is_refused():
    q = configurations()[0]
    named = state(0, q).model_copy(update={"joint_names": ("a", "b", "c", "d", "e")})
    with pytest.raises(ValueError, match="not robot little_john's"):
        check_joints(named, ROBOT)
    check_joints(state(0, q), ROBOT)  # unnamed: q1 .. qn
