"""``--record``: the grader's bags, one per test module, and what the probe hands them.

Fast: the probe's taps on a real graph (each message once), the plugin's bag fixtures
with fakes (a bag that cannot be made is a warning, not a failure), ``grade-batch``'s
folder per student.  Slow: ``grade --record`` on parameter_validation's reference
solution, read back with the MCAP libraries.
"""

from __future__ import annotations

import json
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
import rclpy
from click.testing import CliRunner
from geometry_msgs.msg import Twist
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from nav_msgs.msg import Odometry
from rclpy.context import Context
from rclpy.node import Node
from std_msgs.msg import String

from autograder.core.results import RunResult
from autograder.core.settings import RunSettings
from autograder.grading.run import record_folder
from autograder.plugin.bag import attach_probe, close_bag, open_bag
from autograder.plugin.probe import Probe
from autograder.plugin.reporter import GradingReporter
from autograder.plugin.stash import reporter_key, settings_key

WALL = 20.0
REPO = Path(__file__).resolve().parents[2]
COURSE = REPO / "tests" / "fixtures" / "mini_course"


def _until(condition: Callable[[], bool], wall: float = WALL) -> bool:
    """Wait for ``condition`` (another thread makes it true), with a wall deadline."""
    event = threading.Event()
    for _ in range(int(wall / 0.01)):
        if condition():
            return True
        event.wait(0.01)
    return condition()


# -- the probe's taps ------------------------------------------------------------------

@pytest.fixture
def graph(ros_domain: int) -> Iterator[tuple[Probe, Node, list[tuple[str, str, Any, float]]]]:
    """A probe beside a stand-in world that publishes /odom and subscribes /cmd_vel, and a
    'student' node; what the probe's tap got."""
    context = Context()
    rclpy.init(context=context, domain_id=ros_domain)
    world = SimpleNamespace(now=1.5, PUBLISHES=("/clock", "/odom"), SUBSCRIBES=("/cmd_vel",))
    probe = Probe(context, world)
    tapped: list[tuple[str, str, Any, float]] = []
    probe.add_tap(lambda *seen: tapped.append(seen))
    student = Node("student", context=context)
    try:
        yield probe, student, tapped
    finally:
        student.destroy_node()
        probe.close()
        rclpy.try_shutdown(context=context)


def test_the_probe_hands_over_each_message_once(graph) -> None:
    probe, student, tapped = graph
    status = probe.subscribe(String, "/status")
    odom = probe.subscribe(Odometry, "/odom")
    says = student.create_publisher(String, "/status", 10)
    moves = student.create_publisher(Odometry, "/odom", 10)
    assert _until(lambda: status.publisher_count() == 1 and odom.publisher_count() == 1)
    says.publish(String(data="from the student"))
    moves.publish(Odometry())  # the world's topic: the world's own tap records it
    probe.publish(Twist, "/cmd_vel", Twist())  # the world receives it: recorded there
    probe.publish(Twist, "agent/cmd_vel", Twist())  # only the student hears this one
    probe.publish(String, "/status", String(data="from the probe"))  # comes back to us
    assert _until(lambda: len(status) == 2 and len(odom) == 1)
    assert sorted((topic, kind, stamp) for topic, kind, _, stamp in tapped) == [
        ("/agent/cmd_vel", "geometry_msgs/msg/Twist", 1.5),
        ("/status", "std_msgs/msg/String", 1.5),
        ("/status", "std_msgs/msg/String", 1.5)]
    assert sorted(m.data for topic, _, m, _ in tapped if topic == "/status") == [
        "from the probe", "from the student"]


# -- the plugin's fixtures, with fakes --------------------------------------------------

class FakeBridge:
    def __init__(self) -> None:
        self.sim = SimpleNamespace(lidar=SimpleNamespace())  # no mount yet: (0, 0, 0)
        self.taps: list[Any] = []

    def add_tap(self, tap: Any) -> None:
        self.taps.append(tap)


def _request(tmp_path: Path, record: Path, module: str = "tests/public/test_drive.py"):
    config = SimpleNamespace(stash=pytest.Stash())
    config.stash[settings_key] = RunSettings(exercise="/course/assignments/drive",
                                            record=str(record))
    config.stash[reporter_key] = GradingReporter(None)
    node = SimpleNamespace(path=tmp_path / module, nodeid=module)
    return SimpleNamespace(config=config, node=node)


def test_a_module_is_recorded_in_a_folder_named_after_it(tmp_path: Path) -> None:
    request = _request(tmp_path, tmp_path / "bags")
    bridge = FakeBridge()
    recorder = open_bag(request, bridge, "empty_room")
    assert recorder is not None and bridge.taps == [recorder]
    probe = SimpleNamespace(taps=[])
    probe.add_tap = probe.taps.append
    attach_probe(request, probe)
    assert probe.taps == [recorder]
    recorder("/shout", "std_msgs/msg/String", String(data="HI"), 0.5)
    close_bag(request, recorder)
    data = request.config.stash[reporter_key].data
    assert data["bags"] == {"test_drive": str(tmp_path / "bags" / "test_drive")}
    assert "warnings" not in data
    assert (tmp_path / "bags" / "test_drive" / "test_drive_0.mcap").is_file()
    # A hidden module of the same name gets a folder of its own.
    hidden = _request(tmp_path, tmp_path / "bags", "tests/hidden/test_drive.py")
    hidden.config = request.config
    assert open_bag(hidden, FakeBridge(), "empty_room").directory.name == "test_drive_2"


def test_a_bag_that_cannot_be_made_is_a_warning_not_a_failure(tmp_path: Path) -> None:
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    request = _request(tmp_path, blocker)
    bridge = FakeBridge()
    assert open_bag(request, bridge, "empty_room") is None
    assert bridge.taps == []
    (warning,) = request.config.stash[reporter_key].data["warnings"]
    assert "could not be recorded" in warning and str(blocker) in warning


def test_the_grader_warns_when_the_folder_cannot_be_made(tmp_path: Path) -> None:
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    folder, warnings = record_folder(blocker / "bags")
    assert folder is None and len(warnings) == 1
    assert record_folder(tmp_path / "new" / "bags") == ((tmp_path / "new" / "bags"), [])
    assert (tmp_path / "new" / "bags").is_dir()


def test_results_list_the_bags_and_warnings() -> None:
    result = RunResult(kind="exercise", id="x", title="X", tests=(),
                       bags={"test_a": "/r/test_a"}, warnings=("disk full",))
    shown = result.to_dict()
    assert shown["bags"] == {"test_a": "/r/test_a"} and shown["warnings"] == ["disk full"]
    assert "bags" not in RunResult(kind="exercise", id="x", title="X", tests=()).to_dict()


def test_grade_batch_records_each_student_in_a_folder_of_their_own(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from autograder.commands import grade
    from autograder.grading import run

    monkeypatch.setenv("AUTOGRADER_COURSE", str(COURSE))
    asked: list[Path | None] = []
    monkeypatch.setattr(run, "grade", lambda exercise, path, record=None, **_kw:
                        asked.append(record))
    (tmp_path / "bob").mkdir()
    grade_one, _, _ = grade.batch_item("shout", tmp_path / "bags")
    grade_one(tmp_path / "alice.py")
    grade_one(tmp_path / "bob")
    assert asked == [tmp_path / "bags" / "alice", tmp_path / "bags" / "bob"]


# -- end to end --------------------------------------------------------------------------

def _topics(bag: Path) -> dict[str, list[Any]]:
    (path,) = bag.glob("*.mcap")
    found: dict[str, list[Any]] = {}
    with path.open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        assert reader.get_header().profile == "ros2"
        assert {s.encoding for s in reader.get_summary().schemas.values()} == {"ros2msg"}
        for _, channel, _, message in reader.iter_decoded_messages():
            found.setdefault(channel.topic, []).append(message)
    return found


@pytest.mark.slow
def test_grade_record_writes_a_bag_per_module(tmp_path: Path) -> None:
    from autograder.cli import main

    results = tmp_path / "results.json"
    outcome = CliRunner().invoke(main, [
        "grade", "parameter_validation", str(REPO / "assignments/parameter_validation/solution"),
        "--record", str(tmp_path / "bags"), "--results", str(results)])
    assert outcome.exit_code == 0, outcome.output
    shown = json.loads(results.read_text())
    assert shown["score"] == shown["max_score"] and "warnings" not in shown
    bags = {name: Path(path) for name, path in shown["bags"].items()}
    assert set(bags) == {"test_governor", "test_parameters", "test_startup", "test_world"}
    assert all(path.parent == tmp_path / "bags" for path in bags.values())
    topics = _topics(bags["test_governor"])
    assert {"/clock", "/odom", "/scan", "/tf", "/tf_static"} <= set(topics)
    # The student's output (received by the world) and the agent's input (the probe's).
    assert topics["/cmd_vel"] and topics["/agent/cmd_vel"]
    assert len(topics["/cmd_vel"]) <= len(topics["/agent/cmd_vel"])  # one output per input
    (static,) = topics["/tf_static"]
    assert static.transforms[0].child_frame_id == "base_scan"
