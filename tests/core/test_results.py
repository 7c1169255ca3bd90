"""The results model (autograder.core.results): exact scores, the verdict's rules, and the
JSON results file, which batches resume from and LMS exports, replays and the proofs read.

The file's text is pinned byte for byte (tests/fixtures/results/): a change of shape shows
here first, as a diff of that file, never first in a reader of old results."""

from __future__ import annotations

import dataclasses
import json
import re
from decimal import Decimal
from fractions import Fraction
from pathlib import Path

import pytest

from autograder.core.results import (
    Containment,
    IntervalChart,
    MemoryUse,
    ModulePacing,
    NotRun,
    ProcessBounds,
    RunResult,
    RunTiming,
    StartedProcess,
    TestResult,
    as_decimal,
    exact,
    number,
)
from autograder.render.jsonfile import to_json
from autograder.sandbox.isolation import Isolation

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "results"


def passed(name: str, points: int = 1, core: bool = False) -> TestResult:
    return TestResult(name, name.title(), Fraction(points), Fraction(points), "passed",
                      core=core)


def failed(name: str, points: int = 1, core: bool = False) -> TestResult:
    return TestResult(name, name.title(), Fraction(0), Fraction(points), "failed",
                      message="it did not", hint="try", core=core)


CHART = IntervalChart("cmd_vel", ((0.1, 0.1), (0.25, 0.15), (1, 0.75)), 0.15)


def full_run() -> RunResult:
    """A grading with every field the results file holds (and a chart, which it does not)."""
    return RunResult(
        "exercise", "shout", "Shout", (passed("test_starts", 3, core=True),
                                       dataclasses.replace(failed("test_shouts", 2),
                                                           charts=(CHART,))),
        execution_time=12.3456, log="never in the JSON",
        isolation=Containment.from_dict({**Isolation("strict").to_dict(),
                                         "bounds": {"cgroup": "v2", "processes": "cgroup",
                                                    "memory": "cgroup", "cpu": "cgroup"},
                                         "student_uids": [61007, 61008]}),
        pacing={"test_shout.py": ModulePacing.from_dict(
            {"idle": 3, "budget": 5, "cap": 0, "longest_hold": 0.25})},
        bags={"test_shout.py": "/r/test_shout"}, warnings=("disk full",),
        disturbed=((1001, 1002),),
        timing=RunTiming(child_start=1.234, tests=5.5, total=8.0,
                         modules={"test_shout.py": {"world_start": 0.5, "total": 5.5}},
                         sim_seconds={"tests/public/test_shout.py::test_shouts": 3.5},
                         children=2),
        memory=MemoryUse(185.6, 184.0, 369.6, 209.8))


def test_scores_are_exact_fractions() -> None:
    assert exact(0.1) == Fraction(1, 10)  # through its shortest text, not its binary value
    assert exact("2/3") == Fraction(2, 3) and exact(3) == Fraction(3)
    assert number(Fraction(4)) == 4 and isinstance(number(Fraction(4)), int)
    assert number(Fraction(2, 3)) == 0.6667
    assert as_decimal(Fraction(1, 3), 3) == Decimal("0.333")


def test_seven_of_ten_passes_a_seventy_percent_mark_exactly() -> None:
    tests = tuple(passed(f"t{i}") for i in range(7)) + tuple(failed(f"f{i}") for i in range(3))
    result = RunResult("exercise", "x", "X", tests)
    assert result.fraction == Fraction(7, 10) and result.passed
    assert not dataclasses.replace(result, tests=tests[1:]).passed  # 6 of 9


def test_a_missed_core_test_a_grader_error_or_a_partial_run_never_pass() -> None:
    result = RunResult("exercise", "x", "X", (failed("core", core=True), passed("a", 9)))
    assert result.fraction == Fraction(9, 10)
    assert not result.passed and [t.name for t in result.core_missed] == ["core"]
    fine = RunResult("exercise", "x", "X", (passed("a"),))
    assert fine.passed
    assert not dataclasses.replace(fine, grader_error="boom").passed
    partial = dataclasses.replace(fine, not_run=NotRun(2, Fraction(3)))
    assert not partial.complete and not partial.passed
    assert partial.to_dict()["passed"] is None
    assert not RunResult("exercise", "x", "X", ()).passed  # nothing to pass


def test_a_hidden_test_that_reveals_only_its_status_shows_no_message() -> None:
    test = dataclasses.replace(failed("t"), reveal="status", visibility="hidden")
    assert (test.student_message, test.student_hint) == ("", "")
    assert (failed("t").student_message, failed("t").student_hint) == ("it did not", "try")


def test_what_a_program_wrote_is_shown_harmless() -> None:
    test = TestResult("t", "T", Fraction(0), Fraction(1), "failed", message="\x1b[2Jcleared")
    assert "\x1b" not in test.message and "cleared" in test.message
    result = RunResult("exercise", "x", "X", (), log="a\x1b]0;title\x07b")
    assert "\x1b" not in result.log and "\x07" not in result.log


def test_the_results_file_is_pinned_byte_for_byte() -> None:
    """Readers of results files written before (batches resuming, LMS exports, replays)
    read exactly this text; a new shape is a deliberate change of the fixture."""
    assert to_json(full_run()) == (FIXTURES / "full_run.json").read_text(encoding="utf-8")
    refused = RunResult("exercise", "shout", "Shout", (failed("submission_runs", 5),),
                        refused=True, isolation=Containment.from_dict(
                            Isolation("basic", "the grader does not run as root").to_dict()))
    assert to_json(refused) == (FIXTURES / "refused.json").read_text(encoding="utf-8")


def test_the_results_file_reads_back_to_the_same_file() -> None:
    for name in ("full_run.json", "refused.json"):
        text = (FIXTURES / name).read_text(encoding="utf-8")
        again = RunResult.from_dict(json.loads(text))
        assert to_json(again) == text


def test_every_field_of_the_file_reads_back_typed() -> None:
    run = full_run()
    again = RunResult.from_dict(json.loads(to_json(run)))
    for field in ("kind", "id", "title", "pass_mark", "lang", "grader_error", "isolation",
                  "pacing", "bags", "warnings", "disturbed", "timing", "memory"):
        assert getattr(again, field) == getattr(run, field), field
    assert again.execution_time == 12.346  # rounded to the ms in the file
    assert again.log == ""  # the programs' output goes beside the file, never in it
    assert again.tests[1].charts == ()  # the charts are the HTML report's, never in it
    assert [(t.name, t.score, t.max_score, t.status, t.core) for t in again.tests] == [
        (t.name, t.score, t.max_score, t.status, t.core) for t in run.tests]
    assert isinstance(again.isolation, Containment)
    assert again.isolation.bounds == ProcessBounds("v2", "cgroup", "cgroup", "cgroup")
    assert again.isolation.student_uids == (61007, 61008)


def test_a_chart_reads_back_as_the_child_wrote_it() -> None:
    """The child's raw report carries each chart as :meth:`IntervalChart.to_dict` writes
    it; read back, it is the same chart, its whole times still whole."""
    written = json.dumps(CHART.to_dict())
    assert written == ('{"kind": "intervals", "title": "cmd_vel", '
                       '"points": [[0.1, 0.1], [0.25, 0.15], [1, 0.75]], "limit": 0.15}')
    assert IntervalChart.from_dict(json.loads(written)) == CHART
    assert json.dumps(IntervalChart.from_dict(json.loads(written)).to_dict()) == written
    assert IntervalChart.from_dict({"title": "odom", "points": []}) == IntervalChart("odom")


@pytest.mark.parametrize(("data", "error", "says"), [
    ({"title": "t", "points": [[0.1, 0.1, 0.1]]}, ValueError, "too many values"),
    ({"title": "t", "points": [[0.1]]}, ValueError, "not enough values"),
    ({"title": "t", "points": [0.1]}, TypeError, "cannot unpack"),
    ({"title": "t", "points": [["0.1", 0.1]]}, TypeError, "not a number: '0.1'"),
    ({"title": "t", "points": [[0.1, None]]}, TypeError, "not a number: None"),
    ({"title": "t", "points": [], "limit": True}, TypeError, "not a number: True"),
    ({"title": 3, "points": []}, TypeError, "title is text"),
    ({"kind": "bars", "title": "t", "points": []}, ValueError, "not an intervals chart"),
    ({"title": "t"}, KeyError, "points"),
], ids=["triple", "single", "no-pair", "text-time", "no-gap", "bool-limit", "title",
        "kind", "no-points"])
def test_a_chart_of_another_shape_is_an_error_when_it_is_read(
        data: dict[str, object], error: type[Exception], says: str) -> None:
    """As the other fields' ``from_dict`` fail (a KeyError, TypeError or ValueError), so
    that a reader leaves the chart out, never draws it wrong."""
    with pytest.raises(error, match=re.escape(says)):
        IntervalChart.from_dict(data)


def test_a_quiz_or_a_fault_writes_none_of_the_gradings_fields() -> None:
    shown = RunResult("quiz", "q1", "Quiz one", (passed("q1"),)).to_dict()
    assert shown["quiz"] == "q1" and "exercise" not in shown
    for absent in ("isolation", "pacing", "bags", "warnings", "disturbed", "timing",
                   "memory", "not_run"):
        assert absent not in shown
    again = RunResult.from_dict(shown)
    assert again.kind == "quiz" and again.isolation is None and again.timing is None


def test_containment_reads_an_isolation_with_or_without_its_bounds() -> None:
    basic = Containment.from_dict(Isolation("basic", "not root").to_dict())
    assert (basic.mode, basic.official, basic.network, basic.reason) == (
        "basic", False, True, "not root")
    assert basic.bounds is None and basic.student_uids is None
    assert basic.to_dict() == {**Isolation("basic", "not root").to_dict(), "bounds": None,
                               "student_uids": None}


def test_memory_adds_the_footprint_beside_the_childrens_peaks() -> None:
    peaks = {"grader_mb": 185.6, "student_mb": 184.0, "total_mb": 369.6}
    assert MemoryUse.of(peaks, 209.8).to_dict() == {**peaks, "footprint_mb": 209.8}
    assert MemoryUse.of(peaks, None).to_dict() == peaks  # no sample taken
    assert MemoryUse.of(None, 50.0).to_dict() == {"footprint_mb": 50.0}
    assert MemoryUse.of(None, None) is None and MemoryUse.of({}, None) is None


def test_timing_reads_an_older_file_without_every_field() -> None:
    timing = RunTiming.from_dict({"total": 9.1})
    assert (timing.total, timing.child_start, timing.children, dict(timing.modules)) == (
        9.1, None, 0, {})


def test_not_run_says_what_the_grade_adds() -> None:
    assert NotRun(7, Fraction(12)).describe() == \
        "The grade also runs 7 hidden tests (12 points)."
    assert NotRun(1, Fraction(1)).describe() == "The grade also runs 1 hidden test (1 point)."
    assert NotRun(None, Fraction(5, 2)).describe() == \
        "The grade also runs hidden tests (2.5 points)."
    assert NotRun().describe() == "The grade also runs hidden tests."
    assert NotRun.from_dict(NotRun(3, Fraction(1, 2)).to_dict()) == NotRun(3, Fraction(1, 2))


def test_a_modules_pacing_keeps_its_outcomes_apart_from_its_counters_and_their_order() -> None:
    written = {"free": 20, "budget": 1, "idle": 50, "longest_hold": 0.14, "held_seconds": 0.222,
               "late_deliveries": 1, "bursts": 0, "receipts_awaited": 0, "blocked_waits": 2,
               "late_commands": 0, "latest_command": 0.0}
    pacing = ModulePacing.from_dict(written)
    assert dict(pacing.outcomes) == {"free": 20, "budget": 1, "idle": 50}
    assert pacing.count("budget") == 1 and pacing.count("cap") == 0
    assert pacing.held_seconds == 0.222 and pacing.bursts == 0
    assert json.dumps(pacing.to_dict()) == json.dumps(written)  # as the child wrote it
    older = ModulePacing.from_dict({"idle": 3})  # a file without the counters
    assert older.longest_hold is None and older.to_dict() == {"idle": 3}


def test_a_started_process_is_read_from_the_childs_record_without_its_folder() -> None:
    record = {"pid": 4242, "cgroups": ["/sys/fs/cgroup/ag/p1"], "workdir": "/tmp/ag-x",
              "bounds": {"cgroup": "v2", "processes": "cgroup", "memory": "cgroup",
                         "cpu": None}, "uid": 61007}
    process = StartedProcess.from_record(record)
    assert process == StartedProcess(4242, ("/sys/fs/cgroup/ag/p1",),
                                     ProcessBounds("v2", "cgroup", "cgroup", None), 61007)
    assert StartedProcess.from_record({"pid": 7}) == StartedProcess(7)
