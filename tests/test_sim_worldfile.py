"""World files: the shipped worlds load, and each kind of mistake names file, line, field."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest
import yaml

from content import ContentError
from sim.faultkinds import KINDS
from sim.worldfile import ROBOT_RADIUS, LidarSpec, WorldSpec, load_world, world_names


def test_shipped_worlds_load() -> None:
    assert set(world_names()) >= {"empty_room", "obstacles", "corridor", "wall_ahead"}
    for name in world_names():
        assert load_world(name).name == name


def test_empty_room_has_free_space_ahead() -> None:
    spec = load_world("empty_room")
    assert spec.size == (6.0, 6.0)
    assert (spec.start.x, spec.start.y, spec.start.theta) == (3.0, 3.0, 0.0)
    assert spec.size[0] - spec.start.x - ROBOT_RADIUS > 2.5


def test_corridor_has_a_goal_and_limits_default() -> None:
    spec = load_world("corridor")
    assert spec.goal is not None
    assert spec.limits.max_linear_speed == 1.0 and spec.limits.max_angular_speed == 2.84


def test_every_field_has_a_default_and_a_doc() -> None:
    WorldSpec()
    for f in dataclasses.fields(WorldSpec):
        assert f.metadata.get("doc"), f.name


def test_load_by_path(tmp_path: Path) -> None:
    path = tmp_path / "tiny.yaml"
    path.write_text("size: [2, 2]\nstart: {x: 1, y: 1}\n")
    spec = load_world(path)
    assert spec.name == "tiny" and spec.size == (2.0, 2.0)


def test_unknown_world_name() -> None:
    with pytest.raises(ContentError, match="unknown world"):
        load_world("no_such_world")


BAD = {
    "yaml-error": ("size: [6, 6\nstart: {x: 1}\n", 2, None, "YAML error"),
    "unknown-field": ("size: [6, 6]\nstrat: {x: 1, y: 1}\n", 2, "strat", "unknown field"),
    "missing-field": ("obstacles:\n  circles:\n    - center: [1, 1]\n", 3,
                      "obstacles.circles.0.radius", "required"),
    "missing-fault-kind": ("faults:\n  - start: 1.0\n", 2, "faults.0.kind", "required"),
    "wrong-type": ("size: [6, 6]\nseed: lots\n", 2, "seed", "whole number"),
    "wrong-type-nested": ("start:\n  x: 1\n  y: north\n", 3, "start.y", "number"),
    "start-in-wall": ("walls:\n  - [[1, 0], [1, 6]]\nstart: {x: 1.05, y: 3}\n", 3, "start",
                      "inside wall 0"),
    "start-outside": ("size: [6, 6]\nstart: {x: 7, y: 3}\n", 2, "start", "outside"),
    "start-in-circle": ("obstacles:\n  circles:\n    - {center: [3, 3], radius: 0.3}\n", 1,
                        "start", "inside circle 0"),
    "negative-radius": ("obstacles:\n  circles:\n    - center: [1, 1]\n      radius: -0.2\n", 4,
                        "obstacles.circles.0.radius", "positive"),
    "bad-fraction": ("faults:\n  - {kind: nan, fraction: 2}\n", 2, "faults.0.fraction",
                     "between 0 and 1"),
    "bad-fault-kind": ("faults:\n  - {kind: gremlins}\n", 2, "faults.0.kind", "one of"),
    "field-of-another-kind": ("faults:\n  - {kind: nan}\n  - {kind: dropout, length: 9}\n",
                              3, "faults.1.length", "unknown field"),
    "obstacle-with-end": ("faults:\n  - kind: obstacle\n    box: {center: [1, 1], "
                          "size: [1, 1]}\n    end: 3\n", 4, "faults.0.end", "unknown field"),
    "bad-cmd-vel-type": ("cmd_vel_type: Twistd\n", 1, "cmd_vel_type", "one of 'Twist'"),
    "negative-noise": ("lidar:\n  noise_sigma: -0.01\n", 2, "lidar.noise_sigma",
                       "not be negative"),
    "short-mount": ("lidar:\n  mount: [0.1, 0]\n", 2, "lidar.mount", "3 items"),
    "range-max-below-min": ("lidar: {range_min: 0.5, range_max: 0.4}\n", 1,
                            "lidar.range_max", "above range_min"),
    "no-beams": ("lidar:\n  beams: 0\n", 2, "lidar.beams", "positive"),
    "unknown-lidar-field": ("lidar:\n  sigma: 0.1\n", 2, "lidar.sigma", "unknown field"),
}


@pytest.mark.parametrize("text,line,field,words", BAD.values(), ids=BAD.keys())
def test_malformed_world_names_file_line_field(tmp_path: Path, text: str, line: int,
                                               field: str | None, words: str | None) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ContentError) as info:
        load_world(path)
    err = info.value
    assert err.path == path
    assert err.line == line, str(err)
    if field:
        assert err.field == field, str(err)
    if words:
        assert words in err.message, str(err)


def test_missing_required_field_in_a_fault(tmp_path: Path) -> None:
    """An obstacle fault must say what to place."""
    path = tmp_path / "bad.yaml"
    path.write_text("faults:\n  - kind: obstacle\n    start: 1.0\n")
    with pytest.raises(ContentError) as info:
        load_world(path)
    assert info.value.line == 2 and info.value.field == "faults.0.kind"


def test_lidar_and_cmd_vel_type_default_to_a_turtlebot3_and_the_textbook() -> None:
    spec = load_world("empty_room")
    assert spec.lidar == LidarSpec()
    assert (spec.lidar.noise_sigma, spec.lidar.mount) == (0.01, (-0.032, 0.0, 0.0))
    assert (spec.lidar.beams, spec.lidar.range_min, spec.lidar.range_max) == (360, 0.12, 3.5)
    assert spec.cmd_vel_type == "Twist"


def test_lidar_and_cmd_vel_type_from_the_file(tmp_path: Path) -> None:
    path = tmp_path / "tb3.yaml"
    path.write_text("cmd_vel_type: TwistStamped\nlidar:\n  noise_sigma: 0.02\n"
                    "  mount: [0.05, 0.0, 3.14159]\n  range_max: 8\n")
    spec = load_world(path)
    assert spec.cmd_vel_type == "TwistStamped"
    assert spec.lidar == LidarSpec(noise_sigma=0.02, mount=(0.05, 0.0, 3.14159),
                                   range_max=8.0)


def test_start_pose_angle_is_free() -> None:
    assert math.isclose(load_world("corridor").start.theta, 0.0)



def _faults_file(tmp_path: Path, *faults: dict[str, object]) -> Path:
    path = tmp_path / "faults.yaml"
    path.write_text(yaml.safe_dump({"faults": list(faults)}))
    return path


def _example(kind: str) -> dict[str, object]:
    """A fault of ``kind`` with every field that kind reads."""
    values: dict[str, object] = {"start": 1.0, "end": 2.0, "fraction": 0.5, "length": 9,
                                 "circle": {"center": [1, 1], "radius": 0.2}}
    return {"kind": kind, **{f: values[f] for f in KINDS[kind].fields if f != "box"}}


def test_the_world_file_accepts_exactly_the_kinds_in_the_table(tmp_path: Path) -> None:
    spec = load_world(_faults_file(tmp_path, *(_example(kind) for kind in KINDS)))
    assert [f.kind for f in spec.faults] == list(KINDS)
    with pytest.raises(ContentError) as info:
        load_world(_faults_file(tmp_path, {"kind": "gremlins"}))
    assert info.value.field == "faults.0.kind"
    assert info.value.message == ("must be one of " + ", ".join(repr(k) for k in KINDS)
                                  + ", found 'gremlins'")


@pytest.mark.parametrize("kind", list(KINDS))
def test_each_kind_takes_only_the_fields_it_reads(tmp_path: Path, kind: str) -> None:
    others = {"end", "fraction", "length", "box"} - set(KINDS[kind].fields)
    for field in sorted(others):
        fault = {**_example(kind), field: {"end": 3.0, "fraction": 0.2, "length": 5,
                                           "box": {"center": [2, 2], "size": [1, 1]}}[field]}
        with pytest.raises(ContentError, match="unknown field") as info:
            load_world(_faults_file(tmp_path, fault))
        assert info.value.field == f"faults.0.{field}"
