"""A hand run's parts: which exercise a node file is, the world it runs in, no time limit
but the exercise's other limits, why a node did not come up (the program ended, or no node
of that name), what grading refuses refused here too, and the domain it takes (the
student's own stale nodes stopped, another user's avoided). (Hand runs themselves, through
``sim run --node``: tests/cli/test_sim_node.py.)"""

from __future__ import annotations

import dataclasses
import os
import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest

from autograder.commands import hand_run
from autograder.commands.hand_run import (
    HAND_RUN_SECONDS,
    NodeNotUp,
    NodeRun,
    clear_domain,
    exercise_world,
    node_exercise,
    refuse_unreadable,
)
from autograder.commands.stale import StaleNode
from autograder.core.errors import UsageError
from autograder.core.exercise import Limits, find_exercise
from autograder.i18n import set_language


@pytest.fixture(autouse=True)
def english() -> Iterator[None]:
    set_language("en")
    yield


def test_a_file_named_like_an_exercises_is_that_exercises_node(tmp_path: Path) -> None:
    mine = tmp_path / "velocity_governor.py"
    assert node_exercise(mine, None).id == "parameter_validation"
    assert node_exercise(tmp_path / "my_node.py", None) is None  # a plain node
    assert node_exercise(tmp_path / "my_node.py", "timer_sync").node == "multi_rate_controller"


def test_an_exercises_own_world_file_is_given_by_path() -> None:
    assert exercise_world(find_exercise("parameter_validation")) == "empty_room"
    world = Path(exercise_world(find_exercise("callback_groups")))
    assert world.is_file() and world.name == "supervisor_room.yaml"


def test_a_file_name_two_exercises_share_names_neither(tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    mini = Path(__file__).resolve().parents[1] / "fixtures" / "mini_course" / "assignments"
    for name in ("shout", "shout_again"):
        shutil.copytree(mini / "shout", tmp_path / "assignments" / name)
        yaml = tmp_path / "assignments" / name / "exercise.yaml"
        yaml.write_text(yaml.read_text().replace("id: shout", f"id: {name}"))
    monkeypatch.setenv("AUTOGRADER_COURSE", str(tmp_path))
    assert node_exercise(tmp_path / "shouter.py", None) is None  # a plain node, then
    assert node_exercise(tmp_path / "shouter.py", "shout_again").id == "shout_again"


def test_an_unknown_exercise_is_bad_input(tmp_path: Path) -> None:
    with pytest.raises(UsageError, match="no_such_exercise"):
        node_exercise(tmp_path / "node.py", "no_such_exercise")


def test_no_time_limit_but_the_exercises_other_limits(tmp_path: Path) -> None:
    found = find_exercise("timer_sync")
    run = NodeRun(tmp_path / "node.py", found)
    assert run.node_name == found.node
    assert run.pacing_options() == {"cpu_budget": found.cpu_budget}
    limits = run.limits
    assert (limits.wall_seconds, limits.cpu_seconds) == (HAND_RUN_SECONDS, HAND_RUN_SECONDS)
    assert dataclasses.replace(limits, wall_seconds=found.limits.wall_seconds,
                               cpu_seconds=found.limits.cpu_seconds) == found.limits
    plain = NodeRun(tmp_path / "node.py")
    assert plain.node_name is None and plain.pacing_options() == {}
    assert plain.limits.memory_mb == Limits().memory_mb


@dataclasses.dataclass
class _Program:
    alive: bool
    returncode: int | None = None

    def running(self) -> bool:
        return self.alive


def test_why_a_node_did_not_come_up(tmp_path: Path) -> None:
    found = find_exercise("timer_sync")
    run = NodeRun(tmp_path / "node.py", found, process=_Program(False, 1))
    assert str(run.not_up(20)) == ("Your program exited with status 1 during start-up, "
                                    "before its node was up; its output is above.")
    run.process = _Program(False, -9)
    assert "was killed by signal SIGKILL during start-up" in str(run.not_up(20))
    run.process = _Program(True)
    assert str(run.not_up(20)).splitlines() == [
        f"No node named '{found.node}' appeared on the ROS graph within 20 s.",
        f"Create the node with `super().__init__('{found.node}')` and spin it."]
    plain = NodeRun(tmp_path / "node.py", process=_Program(True))
    assert str(plain.not_up(7.6)) == "No node appeared on the ROS graph within 8 s."
    assert isinstance(plain.not_up(1), NodeNotUp)


def test_what_grading_refuses_is_refused_before_the_world(tmp_path: Path) -> None:
    good = tmp_path / "good" / "node.py"
    good.parent.mkdir()
    good.write_text("import rclpy\nrclpy.init()\nnode = rclpy.create_node('mine')\n")
    refuse_unreadable(good)  # nothing raised
    plain = tmp_path / "plain" / "node.py"
    plain.parent.mkdir()
    plain.write_text("print('hi')\n")
    with pytest.raises(UsageError, match="creates no ROS node"):
        refuse_unreadable(plain)
    linked = tmp_path / "linked" / "node.py"
    linked.parent.mkdir()
    linked.symlink_to(good)
    with pytest.raises(UsageError):
        refuse_unreadable(linked)
    broken = tmp_path / "broken" / "node.py"
    broken.parent.mkdir()
    broken.write_text("def main(:\n    pass\n")
    with pytest.raises(UsageError, match="line 1"):
        refuse_unreadable(broken)


@pytest.fixture
def on_domain(monkeypatch: pytest.MonkeyPatch):
    """Stale nodes on a domain as ``stale.find`` would report them; what was stopped."""
    stopped: list[list[StaleNode]] = []
    found: dict[int, list[StaleNode]] = {}
    monkeypatch.setattr(hand_run.stale, "find", lambda domain: found.get(domain, []))
    monkeypatch.setattr(hand_run.stale, "stop", stopped.append)
    monkeypatch.setattr(hand_run.stale, "free_domain", lambda avoid: 42)
    monkeypatch.delenv("ROS_DOMAIN_ID", raising=False)
    return found, stopped


def test_a_clear_domain_is_taken_as_given(on_domain, monkeypatch, capsys) -> None:
    assert clear_domain(None) == 0
    assert clear_domain(5) == 5
    monkeypatch.setenv("ROS_DOMAIN_ID", "9")
    assert clear_domain(None) == 9
    assert on_domain[1] == [] and capsys.readouterr() == ("", "")


def test_the_students_own_stale_node_is_stopped_and_said(on_domain, tmp_path, capsys) -> None:
    found, stopped = on_domain
    mine = StaleNode(4321, os.getuid(), tmp_path, "driver.py")
    found[3] = [mine]
    assert clear_domain(3) == 3
    assert stopped == [[mine]]
    err = capsys.readouterr().err
    assert "A node of yours (driver.py, pid 4321) was still running on ROS domain 3" in err


def test_another_users_stale_node_moves_the_run_to_a_free_domain(on_domain, tmp_path,
                                                                 capsys) -> None:
    found, stopped = on_domain
    theirs = StaleNode(999, os.getuid() + 1, tmp_path, "")
    found[3] = [theirs]
    assert clear_domain(3) == 42
    assert stopped == []  # only they may stop it
    err = capsys.readouterr().err
    assert "this run uses domain 42 instead" in err
    assert "`autograder sim drive --domain 42`" in err
