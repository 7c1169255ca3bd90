"""Test modules shared out among child pytests and their reports merged
(autograder.grading.module_groups), and one grading run that way end to end."""

from __future__ import annotations

import dataclasses
import resource
from pathlib import Path

import pytest

from autograder.core import report
from autograder.core.exercise import load_exercise
from autograder.core.report import RawReport, RawTest
from autograder.core.results import IntervalChart, RunResult
from autograder.grading.children import Child, Ended
from autograder.grading.module_groups import children_for, find_modules, merge, share_out
from autograder.grading.run import GRADER_FAULT, verdict
from sim.contact import Contact
from sim.recorder import Recording, Sample

PUBLIC, HIDDEN_A, HIDDEN_B = "tests/public/test_p.py", "tests/hidden/test_a.py", \
    "tests/hidden/test_b.py"
ORDER = [PUBLIC, HIDDEN_A, HIDDEN_B]


def _test(module: str, name: str, done: bool = True) -> RawTest:
    return RawTest(nodeid=f"{module}::{name}", name=name, label=name, max_score=1,
                   visibility="visible", reveal="message", done=done, status="passed")


def _child(*tests: RawTest, **data: object) -> RawReport:
    return RawReport(tests=list(tests), data=dict(data))


def test_tests_follow_collection_order_whatever_child_ran_them() -> None:
    first = _child(_test(HIDDEN_A, "a1"), _test(HIDDEN_A, "a2"))
    second = _child(_test(PUBLIC, "p1"), _test(HIDDEN_B, "b1"), _test(PUBLIC, "p2"))
    merged = merge([first, second], ORDER)
    assert [t.name for t in merged.tests] == ["p1", "p2", "a1", "a2", "b1"]


def test_a_module_not_in_the_order_goes_last_and_one_child_keeps_its_own_order() -> None:
    stray = _test("tests/other/test_z.py", "z")
    merged = merge([_child(stray), _child(_test(HIDDEN_B, "b"))], ORDER)
    assert [t.name for t in merged.tests] == ["b", "z"]
    alone = _child(_test(HIDDEN_B, "b"), _test(PUBLIC, "p"))
    assert [t.name for t in merge([alone], ORDER).tests] == ["b", "p"]


def test_one_forged_child_forges_the_whole() -> None:
    merged = merge([_child(_test(PUBLIC, "p")), RawReport(forged=True)], ORDER)
    assert merged.forged and merged.tests == []


def test_data_is_joined_lists_concatenated_first_test_earliest() -> None:
    first = _child(_test(PUBLIC, "p"), recordings={"test_p.py": {"r": 1}},
                   pacing={"test_p.py": {"idle": 3}}, timing={PUBLIC: {"total": 2.0}},
                   bags={"test_p": "/b/test_p"}, warnings=["w1"], logs={"p": "out p"},
                   processes=[{"pid": 1}], startup_seconds=[0.5], first_test_at=20.0)
    second = _child(_test(HIDDEN_A, "a"), recordings={"test_a.py": {"r": 2}},
                    pacing={"test_a.py": {"idle": 4}}, timing={HIDDEN_A: {"total": 5.0}},
                    bags={"test_a": "/b/test_a"}, warnings=["w2"], logs={"a": "out a"},
                    processes=[{"pid": 2}], startup_seconds=[0.7], first_test_at=10.0)
    data = merge([first, second], ORDER).data
    assert set(data["recordings"]) == {"test_p.py", "test_a.py"}
    assert data["pacing"] == {"test_p.py": {"idle": 3}, "test_a.py": {"idle": 4}}
    assert set(data["timing"]) == {PUBLIC, HIDDEN_A}
    assert set(data["bags"]) == {"test_p", "test_a"}
    assert data["warnings"] == ["w1", "w2"] and data["startup_seconds"] == [0.5, 0.7]
    assert data["logs"] == {"p": "out p", "a": "out a"}
    assert [p["pid"] for p in data["processes"]] == [1, 2]
    assert data["first_test_at"] == 10.0


def test_not_run_comes_from_the_one_child_that_counted() -> None:
    counted = {"tests": 3, "points": "4"}
    data = merge([_child(_test(PUBLIC, "p")), _child(_test(PUBLIC, "q"), not_run=counted)],
                 ORDER).data
    assert data["not_run"] == counted
    assert "not_run" not in merge([_child(_test(PUBLIC, "p"))], ORDER).data


def test_peak_memory_is_summed_over_children_running_at_once() -> None:
    memory = [{"grader_mb": 90.0, "student_mb": 80.0, "total_mb": 170.0},
              {"grader_mb": 95.5, "student_mb": 70.0, "total_mb": 165.5}]
    data = merge([_child(memory=m) for m in memory], ORDER).data
    assert data["memory"] == {"grader_mb": 185.5, "student_mb": 150.0, "total_mb": 335.5}


def test_output_logs_are_joined() -> None:
    first, second = RawReport(output_log="==> p <==\nhi"), RawReport()
    third = RawReport(output_log="==> a <==\nyo")
    assert merge([first, second, third], ORDER).output_log == "==> p <==\nhi\n\n==> a <==\nyo"


@pytest.mark.parametrize(("requested", "modules", "cores", "expected"), [
    ("auto", 4, 2.0, 2), ("auto", 1, 8.0, 1), ("auto", 3, 0.5, 1), ("auto", 2, 16.0, 2),
    (1, 5, 8.0, 1), (3, 5, 1.0, 3), (8, 2, 8.0, 2),
], ids=["cores-bound", "one-module", "under-a-core", "module-bound", "one", "explicit",
        "no-more-than-modules"])
def test_how_many_children(requested: int | str, modules: int, cores: float,
                           expected: int) -> None:
    assert children_for(requested, modules, cores) == expected  # type: ignore[arg-type]


def test_modules_are_shared_round_robin_and_same_named_ones_stay_together() -> None:
    modules = [Path(p) for p in ("pub/test_a.py", "pub/test_b.py", "hid/test_c.py",
                                 "hid/test_a.py", "hid/test_d.py")]
    groups = share_out(modules, 2)
    assert [[str(m) for m in g] for g in groups] == [
        ["pub/test_a.py", "hid/test_c.py", "hid/test_a.py"],
        ["pub/test_b.py", "hid/test_d.py"]]
    assert share_out(modules[:1], 3) == [modules[:1]]


def test_modules_are_found_as_pytest_collects_them(tmp_path: Path) -> None:
    public, hidden = tmp_path / "public", tmp_path / "hidden"
    for path in (public / "test_z.py", public / "test_b.py", public / "helpers.py",
                 hidden / "test_a.py", hidden / "sub" / "test_c.py", hidden / "x_test.py"):
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("")
    found = [p.relative_to(tmp_path).as_posix() for p in find_modules([public, hidden])]
    assert found == ["public/test_b.py", "public/test_z.py", "hidden/sub/test_c.py",
                     "hidden/test_a.py", "hidden/x_test.py"]


def _collected(folder: Path) -> list[str]:
    """The node ids pytest itself collects from an exercise's public and hidden tests."""
    import subprocess
    import sys

    out = subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "--collect-only", "-q",
         "--rootdir", ".", "tests/public", "tests/hidden"],
        cwd=folder, capture_output=True, text=True, check=True).stdout
    return [line for line in out.splitlines() if "::" in line]


@pytest.mark.slow
def test_a_grading_runs_its_modules_in_two_children_on_two_domains(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from autograder.core.exercise import find_exercise
    from autograder.grading.run import grade

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setenv("PYTHONDONTWRITEBYTECODE", "1")  # the children cache theirs anyway
    exercise = find_exercise("parameter_validation")
    result = grade(exercise, None, module_jobs=2)
    assert result.grader_error is None, result.grader_details
    assert result.score == result.max_score == exercise.points
    assert [t.nodeid for t in result.tests] == _collected(exercise.folder)
    domains = result.domains
    assert len(domains) == 2 and len(set(domains)) == 2
    assert result.timing is not None and result.timing.children == 2
    modules = {t.nodeid.split("::")[0] for t in result.tests}
    assert set(result.timing.modules) == modules
    assert set(result.pacing) == {m.rpartition("/")[2] for m in modules}
    assert set(result.recordings) == set(result.pacing)
    # The tree's PSS: this process, two children and a student each at a time, each
    # counting at most its resident size (PSS divides the pages it shares).
    memory = result.memory
    assert memory is not None and memory.footprint_mb is not None
    own_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    assert 0 < memory.footprint_mb < (memory.total_mb or 0.0) + own_mb
    # The children kept their bytecode (hidden tests' included) in the user's cache, and
    # wrote none beside the course's sources.
    cached = tmp_path / "rclpy-autograder" / "pycache"
    hidden = next((exercise.folder / "tests" / "hidden").glob("test_*.py"))
    assert list((cached / hidden.parent.relative_to("/")).glob(f"{hidden.stem}.*.pyc"))
    assert not list(exercise.folder.rglob("__pycache__"))


def test_children_write_no_bytecode_where_the_cache_cannot_be_made(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from autograder.grading.children import bytecode_env

    (tmp_path / "rclpy-autograder").write_text("a file where the folder would go")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    env = bytecode_env({"PYTHONPYCACHEPREFIX": "/elsewhere", "PATH": "/usr/bin"})
    assert env == {"PYTHONDONTWRITEBYTECODE": "1", "PATH": "/usr/bin"}
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    env = bytecode_env({"PYTHONDONTWRITEBYTECODE": "1"})
    assert env == {"PYTHONPYCACHEPREFIX": str(tmp_path / "cache" / "rclpy-autograder" / "pycache")}


SHOUT = Path(__file__).parents[1] / "fixtures" / "mini_course" / "assignments" / "shout"


def _ended(*tests: RawTest, returncode: int | None = 1, timed_out: bool = False,
           log: str = "") -> Ended:
    return Ended(RawReport(tests=list(tests)), returncode, timed_out, log, 0.0)


def _outcome(*ended: Ended) -> RunResult:
    raw = merge([e.raw for e in ended], ORDER)
    return verdict(load_exercise(SHOUT), raw, ended, 1.0)


def test_a_child_stopped_at_the_time_limit_says_so_for_its_own_tests_only() -> None:
    unfinished = dataclasses.replace(_test(HIDDEN_A, "a"), done=False, status="error")
    result = _outcome(_ended(_test(PUBLIC, "p"), _test(HIDDEN_B, "b"), returncode=0),
                      _ended(unfinished, returncode=None, timed_out=True))
    assert [(t.name, t.status) for t in result.tests] == [
        ("p", "passed"), ("a", "failed"), ("b", "passed")]
    assert "time limit" in result.tests[1].message
    assert result.grader_error is None and result.timed_out is True
    assert result.score == 2


def test_a_child_that_broke_is_the_graders_fault_with_its_own_log() -> None:
    result = _outcome(_ended(_test(PUBLIC, "p"), returncode=0, log="fine"),
                      _ended(returncode=2, log="ImportError in test_a.py"))
    assert result.grader_error == GRADER_FAULT
    assert "ImportError in test_a.py" in result.grader_details
    assert "fine" not in result.grader_details
    assert [t.name for t in result.tests] == ["p"]  # the others' results still count


def test_each_modules_recording_is_read_back_and_one_unreadable_left_out() -> None:
    recorded = Recording(world="obstacles", samples=[Sample(0.02, 3.0, 3.0, 0.0, 0.1, 0.0)],
                         collisions=[Contact(0.02, 3.0, 3.0, "box 0")])
    ended = _ended(_test(PUBLIC, "p"), returncode=0)
    raw = dataclasses.replace(ended.raw, data={"recordings": {
        "test_p.py": recorded.to_dict(), "test_a.py": {"trajectory": [[0.1, 3.0]]}}})
    result = verdict(load_exercise(SHOUT), raw, [ended], 1.0)
    assert list(result.recordings) == ["test_p.py"]
    assert result.recordings["test_p.py"] == recorded
    assert [(t.name, t.status) for t in result.tests] == [("p", "passed")]  # graded as ever


def test_each_tests_charts_are_read_back_and_one_unreadable_left_out() -> None:
    """A chart is only a picture in the report: one the raw report carries in another
    shape (a point that is not a pair, a time that is not a number) is not drawn, and the
    test is graded as ever."""
    drawn = IntervalChart("cmd_vel", ((0.1, 0.1), (0.2, 0.1)), 0.15)
    unreadable = [{"kind": "intervals", "title": "odom", "points": [[0.1, 0.1, 0.1]]},
                  {"kind": "intervals", "title": "odom", "points": [["0.1", 0.1]]},
                  {"kind": "intervals", "title": "odom", "points": [0.1]},
                  {"kind": "bars", "title": "odom", "points": []}, {"title": "odom"}, []]
    charted = dataclasses.replace(_test(PUBLIC, "p"),
                                  charts=[drawn.to_dict(), *unreadable, drawn.to_dict()])
    result = _outcome(_ended(charted, returncode=0))
    assert result.tests[0].charts == (drawn, drawn)
    assert [(t.name, t.status) for t in result.tests] == [("p", "passed")]


@pytest.mark.parametrize(("options", "expected"), [
    (["--jobs", "1"], "auto"), (["--jobs", "2"], 1), ([], 1), (["--jobs", "auto"], 1),
    (["--jobs", "2", "--module-jobs", "3"], 3),
], ids=["one-grading-at-a-time", "several", "default-auto", "auto", "explicit"])
def test_grade_batch_runs_modules_at_once_only_when_it_grades_one_at_a_time(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, options: list[str],
        expected: int | str) -> None:
    from click.testing import CliRunner

    from autograder.cli import main
    from autograder.grading import run

    monkeypatch.setenv("AUTOGRADER_COURSE", str(SHOUT.parent.parent))
    asked: list[int | str] = []

    def fake_grade(exercise, path, *, module_jobs="auto", **_kw):
        asked.append(module_jobs)
        return RunResult(kind="exercise", id="shout", title="Shout", tests=())

    monkeypatch.setattr(run, "grade", fake_grade)
    monkeypatch.setattr("autograder.grading.capacity.auto_chooser",
                        lambda report=None: lambda wall, result, at_once, left: 2)
    (tmp_path / "subs").mkdir()
    for student in ("alice", "bob"):
        (tmp_path / "subs" / f"{student}.py").write_text("")
    outcome = CliRunner().invoke(main, ["grade-batch", "shout", str(tmp_path / "subs"),
                                        "--csv", str(tmp_path / "g.csv"), "--out",
                                        str(tmp_path / "out"), *options])
    assert outcome.exit_code == 0, outcome.output
    assert asked == [expected, expected]


def test_a_childs_report_is_parsed_again_only_when_it_changed(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path, key = tmp_path / "report.json", b"k" * 32
    child = Child(None, path, key, tmp_path / "pytest.log", 0.0)  # type: ignore[arg-type]
    assert child.reported_tests() == []  # no report yet
    parsed = []
    real_read = report.read
    monkeypatch.setattr(report, "read", lambda *a, **kw: parsed.append(1) or real_read(*a, **kw))
    report.write(path, [_test(PUBLIC, "test_one")], {}, key)
    assert [t.name for t in child.reported_tests()] == ["test_one"]
    assert [t.name for t in child.reported_tests()] == ["test_one"]
    assert len(parsed) == 1  # unchanged: the tests as last read
    report.write(path, [_test(PUBLIC, "test_one"), _test(PUBLIC, "test_two")], {}, key)
    assert [t.name for t in child.reported_tests()] == ["test_one", "test_two"]
    assert len(parsed) == 2
    report.write(path, [_test(PUBLIC, "test_one")], {}, b"x" * 32)  # not ours: forged
    assert child.reported_tests() == []


def test_each_childs_sim_seconds_are_joined_for_the_floor() -> None:
    first = RawReport(tests=[], data={"sim_seconds": {"tests/public/test_a.py::t1": 2.5}})
    second = RawReport(tests=[], data={"sim_seconds": {"tests/hidden/test_b.py::t2": 4.0}})
    merged = merge([first, second], ["tests/public/test_a.py", "tests/hidden/test_b.py"])
    assert merged.data["sim_seconds"] == {"tests/public/test_a.py::t1": 2.5,
                                          "tests/hidden/test_b.py::t2": 4.0}
