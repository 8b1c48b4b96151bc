"""Type names and REP 2011 type hashes equal ROS 2's own.

Where the pinned values come from (none of them computed by gazebot or rosbags):

* ``std_msgs/msg/String``: the value issue 18 quotes from ROS 2.
* every standard type: computed with ``zenoh-ros2-sdk`` 0.1.8
  (``zenoh_ros2_sdk.utils.compute_type_hash_from_msg``, its own REP 2011 implementation) from
  ROS 2 Jazzy's ``.msg`` files: ``ros2/common_interfaces`` (branch ``jazzy``) for std_msgs,
  geometry_msgs, sensor_msgs, trajectory_msgs and diagnostic_msgs, ``ros2/rcl_interfaces``
  (``jazzy``) for builtin_interfaces and ``ros2/geometry2`` (``jazzy``) for tf2_msgs.
* ``builtin_interfaces/msg/Time``, ``std_msgs/msg/Header`` and ``sensor_msgs/msg/JointState``
  also agree with the values pinned in ``ros2_pyterfaces``' tests (``test_hash_rihs01``), a
  third implementation.
* ``gazebot_msgs``: computed the same way with ``zenoh-ros2-sdk`` from our ``.msg`` files; a
  change to a ``.msg`` file changes its hash, and must be deliberate (ROS 2 nodes built against
  the old definition stop matching). When ``zenoh-ros2-sdk`` is installed, the last test
  recomputes them from the files.
"""

from __future__ import annotations

import pytest

from gazebot.io.ros2 import MessageError, dds_type_name, ros_type_name, type_info, typestore
from gazebot.io.ros2.typestore import msgs_package_dir, read_msg_files

ROS2_HASHES = {
    "std_msgs/msg/String":
        "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18",
    "std_msgs/msg/Header":
        "RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01",
    "builtin_interfaces/msg/Time":
        "RIHS01_b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197",
    "builtin_interfaces/msg/Duration":
        "RIHS01_e8d009f659816f758b75334ee1a9ca5b5c0b859843261f14c7f937349599d93b",
    "geometry_msgs/msg/PointStamped":
        "RIHS01_4c0296af86e01e562e9e0405d138a01537247580076c58ea38d7923ac1045897",
    "geometry_msgs/msg/PoseStamped":
        "RIHS01_10f3786d7d40fd2b54367835614bff85d4ad3b5dab62bf8bca0cc232d73b4cd8",
    "geometry_msgs/msg/TransformStamped":
        "RIHS01_0a241f87d04668d94099cbb5ba11691d5ad32c2f29682e4eb5653424bd275206",
    "tf2_msgs/msg/TFMessage":
        "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087",
    "sensor_msgs/msg/JointState":
        "RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e",
    "trajectory_msgs/msg/JointTrajectory":
        "RIHS01_179b33eba59d676f6d967ac71fe35e7ca2f64b2f3928f4a018cec115e213796e",
    "diagnostic_msgs/msg/DiagnosticArray":
        "RIHS01_5a8a36efb05fb25070fa0fb3810290c0e6cd4862b54a8fb975a1ee8dc55a333e",
    "sensor_msgs/msg/CompressedImage":
        "RIHS01_15640771531571185e2efc8a100baf923961a4d15d5569652e6cb6691e8e371a",
    "std_msgs/msg/Float64":
        "RIHS01_705ba9c3d1a09df43737eb67095534de36fd426c0587779bda2bc51fe790182a",
}

GAZEBOT_HASHES = {
    "gazebot_msgs/msg/EyeState":
        "RIHS01_c87d5f7003463bb8acaafcc77d5194f88dc920c24b44b9f3d8e412cb4fbd161a",
    "gazebot_msgs/msg/HandoverPhase":
        "RIHS01_e5e980c673daf77ddd12c85b983e60dfdd925192174442880f6ff542a4da28e7",
    "gazebot_msgs/msg/HandoverEvent":
        "RIHS01_da5fd0cbaa34a180f21f69cc9390e00e7cc90f34002f18279c7ba8ec757630d3",
    "gazebot_msgs/msg/GripperState":
        "RIHS01_f5675e4d3866560640551bd1647d5e925dce267667d0c0d5d69ed96c844417d0",
    "gazebot_msgs/msg/LoadShare":
        "RIHS01_514afbc19298db51910817fd66ebb29e39fbf8acd523ed2d0b46163a8e2853a6",
}


@pytest.mark.parametrize("name", sorted(ROS2_HASHES))
def test_standard_type_hash_equals_ros2s(name: str) -> None:
    assert type_info(typestore(), name).hash == ROS2_HASHES[name]


@pytest.mark.parametrize("name", sorted(GAZEBOT_HASHES))
def test_gazebot_msgs_type_hash_is_pinned(name: str) -> None:
    assert type_info(typestore(), name).hash == GAZEBOT_HASHES[name]


def test_every_gazebot_msgs_file_is_registered_and_pinned() -> None:
    assert set(read_msg_files(msgs_package_dir())) == set(GAZEBOT_HASHES)


def test_dds_type_name_round_trips() -> None:
    dds = dds_type_name("geometry_msgs/msg/PointStamped")
    assert dds == "geometry_msgs::msg::dds_::PointStamped_"
    assert ros_type_name(dds) == "geometry_msgs/msg/PointStamped"
    assert type_info(typestore(), "gazebot_msgs/msg/EyeState").dds_name == (
        "gazebot_msgs::msg::dds_::EyeState_"
    )


@pytest.mark.parametrize("bad", ["PointStamped", "geometry_msgs/srv/X", "a//b", "a/msg/"])
def test_malformed_type_name_is_a_message_error(bad: str) -> None:
    with pytest.raises(MessageError):
        dds_type_name(bad)


def test_unknown_type_is_a_message_error() -> None:
    with pytest.raises(MessageError, match="unknown message type"):
        type_info(typestore(), "gazebot_msgs/msg/Nope")


def test_cmakelists_generates_every_msg_file() -> None:
    cmake = (msgs_package_dir() / "CMakeLists.txt").read_text()
    for name in read_msg_files(msgs_package_dir()):
        assert f'"msg/{name.rsplit("/", 1)[1]}.msg"' in cmake


def test_gazebot_msgs_hashes_match_zenoh_ros2_sdk() -> None:
    """An independent REP 2011 implementation, from the same .msg files and ROS 2's own
    dependency definitions (as rosbags renders them)."""
    utils = pytest.importorskip("zenoh_ros2_sdk.utils", reason="zenoh-ros2-sdk not installed")
    store = typestore()
    files = read_msg_files(msgs_package_dir())
    for name, text in files.items():
        deps = {}
        full, _ = store.generate_msgdef(name, ros_version=2)
        for block in full.split("=" * 80 + "\nMSG: ")[1:]:
            dep, body = block.split("\n", 1)
            pkg, _, short = dep.partition("/")
            deps[f"{pkg}/msg/{short}"] = body
        assert utils.compute_type_hash_from_msg(name, text, deps) == GAZEBOT_HASHES[name]


def test_gazebot_msgs_parse_with_ros2s_own_msg_parser() -> None:
    """ROS 2's ``rosidl_adapter`` (what colcon runs on .msg files) parses every file to the
    fields gazebot registers (skipped where ROS 2's Python packages are not installed)."""
    parser = pytest.importorskip("rosidl_adapter.parser", reason="ROS 2 rosidl not installed")
    store = typestore()
    for name, text in read_msg_files(msgs_package_dir()).items():
        pkg, _, short = name.split("/")
        spec = parser.parse_message_string(pkg, short, text)
        assert [f.name for f in spec.fields] == [f for f, _ in store.fielddefs[name][1]]
