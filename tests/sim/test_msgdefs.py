"""ROS 2 message definitions as rosbag2 stores them: a type's name from its class, its full
text (its own, then each type it uses once, depth first, after the delimiter, as
rosbag2's ``LocalMessageDefinitionSource`` joins them) from the installed ``.msg`` files,
and its type hash from the ``.json`` beside them; TFMessage embedded, with the hash rosidl
computes."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from geometry_msgs.msg import Twist

from sim import msgdefs


def test_the_embedded_tf_message_hash_is_the_one_rosidl_computes() -> None:
    generator = pytest.importorskip("rosidl_generator_type_description")
    share = Path(sys.prefix) / "share" / "geometry_msgs" / "msg" / "TransformStamped.json"
    stamped = json.loads(share.read_text())["type_description_msg"]
    types = {t["type_name"]: t for t in stamped["referenced_type_descriptions"]}
    types[stamped["type_description"]["type_name"]] = stamped["type_description"]
    unbounded_sequence_of_nested = 145
    description = {
        "type_description": {"type_name": msgdefs.TF_MESSAGE, "fields": [{
            "name": "transforms", "default_value": "",
            "type": {"type_id": unbounded_sequence_of_nested, "capacity": 0,
                     "string_capacity": 0,
                     "nested_type_name": "geometry_msgs/msg/TransformStamped"}}]},
        "referenced_type_descriptions": [types[name] for name in sorted(types)]}
    assert generator.calculate_type_hash(description) == msgdefs.type_hash(msgdefs.TF_MESSAGE)


def test_type_names_and_full_text_follow_rosbag2() -> None:
    assert msgdefs.type_name(Twist) == "geometry_msgs/msg/Twist"
    assert msgdefs.type_name(type("Odd", (), {"__module__": "odd"})) == "odd/msg/Odd"
    text = msgdefs.full_text("geometry_msgs/msg/Twist")
    own, _, rest = text.partition("\n" + "=" * 80 + "\n")
    assert "Vector3  linear" in own
    assert rest.startswith("MSG: geometry_msgs/Vector3\n")
    with pytest.raises(msgdefs.DefinitionNotFound):
        msgdefs.full_text("no_such_pkg/msg/Nothing")


def _package(prefix: Path, package: str, messages: dict[str, str],
             hashes: dict[str, str] | None = None) -> None:
    folder = prefix / "share" / package / "msg"
    folder.mkdir(parents=True)
    for name, text in messages.items():
        (folder / f"{name}.msg").write_text(text)
    for name, value in (hashes or {}).items():
        (folder / f"{name}.json").write_text(json.dumps({"type_hashes": [
            {"type_name": f"{package}/msg/Other", "hash_string": "RIHS01_other"},
            {"type_name": f"{package}/msg/{name}", "hash_string": value}]}))


def test_each_dependency_once_depth_first_in_rosbag2s_order(tmp_path, monkeypatch):
    """Package-relative and qualified types alike; primitives, arrays and constants aside."""
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path))
    _package(tmp_path, "msgdefs_test_a", {
        "Top": "# a comment\nZeta last\nmsgdefs_test_b/Alpha[] firsts\nfloat64 x\n"
               "uint8 MODE=1\nstring<=5 name\nZeta[3] again\n",
        "Zeta": "msgdefs_test_b/Alpha alpha\nbool flag\n"})
    _package(tmp_path, "msgdefs_test_b", {"Alpha": "int32 n\n"})
    text = msgdefs.full_text("msgdefs_test_a/msg/Top")
    parts = text.split("\n" + msgdefs.DELIMITER)
    assert parts[0] == ("# a comment\nZeta last\nmsgdefs_test_b/Alpha[] firsts\nfloat64 x\n"
                        "uint8 MODE=1\nstring<=5 name\nZeta[3] again\n")
    assert parts[1:] == ["MSG: msgdefs_test_a/Zeta\nmsgdefs_test_b/Alpha alpha\nbool flag\n",
                         "MSG: msgdefs_test_b/Alpha\nint32 n\n"]
    assert msgdefs.DELIMITER == "=" * 80 + "\n"


def test_a_missing_dependency_is_not_found(tmp_path, monkeypatch):
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path))
    _package(tmp_path, "msgdefs_test_c", {"Uses": "msgdefs_test_gone/Thing thing\n"})
    with pytest.raises(msgdefs.DefinitionNotFound, match="msgdefs_test_gone/Thing"):
        msgdefs.full_text("msgdefs_test_c/msg/Uses")
    with pytest.raises(msgdefs.DefinitionNotFound):
        msgdefs.full_text("not a type name")


def test_the_hash_from_the_json_beside_the_msg(tmp_path, monkeypatch):
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path))
    _package(tmp_path, "msgdefs_test_d", {"Hashed": "int8 a\n", "Bare": "int8 b\n"},
             {"Hashed": "RIHS01_abc"})
    (tmp_path / "share" / "msgdefs_test_d" / "msg" / "Broken.json").write_text("{")
    assert msgdefs.type_hash("msgdefs_test_d/msg/Hashed") == "RIHS01_abc"
    assert msgdefs.type_hash("msgdefs_test_d/Hashed") == "RIHS01_abc"  # without /msg/
    assert msgdefs.type_hash("msgdefs_test_d/msg/Bare") == ""  # no .json: not said
    assert msgdefs.type_hash("msgdefs_test_d/msg/Broken") == ""
    assert msgdefs.type_hash("geometry_msgs/msg/Twist").startswith("RIHS01_")  # installed
