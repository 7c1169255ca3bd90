"""The JSON results file (autograder.render.jsonfile): the results model's dictionary as
UTF-8 text, indented, ending in a newline; its shape is tests/core/test_results.py's."""

from __future__ import annotations

import dataclasses
import json
from fractions import Fraction
from pathlib import Path

from graded_result import graded_result as result

from autograder.core.results import (
    Containment,
    MemoryUse,
    ModulePacing,
    ProcessBounds,
    RunResult,
    RunTiming,
    TestResult,
)
from autograder.render.jsonfile import FORMAT, to_json


def urdu() -> RunResult:
    test = TestResult("test_speaks", "بولتا ہے", Fraction(1), Fraction(1), "passed")
    return RunResult("exercise", "shout", "آواز", (test,), lang="ur")


def test_the_file_is_readable_utf8_indented_with_a_last_newline() -> None:
    text = to_json(urdu())
    assert "آواز" in text and "\\u" not in text  # Urdu as itself, not escaped
    assert text.endswith("}\n") and text.startswith('{\n  "exercise": "shout",\n')
    assert json.loads(text) == urdu().to_dict()


def test_the_format_writes_results_json_in_a_batch() -> None:
    assert FORMAT.batch_file == "results.json"
    assert FORMAT.name == "results"
    assert FORMAT.render(urdu(), Path(".")) == to_json(urdu())


def test_json_has_the_results_shape():
    data = json.loads(to_json(result()))
    assert data["exercise"] == "timer_sync"
    assert (data["score"], data["max_score"], data["passed"]) == (2.5, 7, False)
    assert [t["status"] for t in data["tests"]] == ["passed", "failed", "failed", "passed",
                                                     "failed"]
    assert {"name", "score", "max_score", "status", "message", "visibility"} <= set(
        data["tests"][0])


def test_the_results_file_reads_back_with_its_timing_memory_and_pacing():
    """A batch resuming from its reports, and the proofs' diagnoses, read these back."""
    data = {"isolation": Containment("strict", True, True, False, True,
                                     bounds=ProcessBounds("v2", "cgroup", "cgroup", None),
                                     student_uids=(61003,)),
            "timing": RunTiming(child_start=None, total=9.1, tests=8.0,
                                modules={"test_a.py": {"total": 8.0}}, children=1),
            "memory": MemoryUse(grader_mb=90.0, student_mb=80.0, total_mb=170.0,
                                footprint_mb=120.5),
            "pacing": {"test_a.py": ModulePacing({"idle": 10}, late_deliveries=1)},
            "warnings": ("w",), "bags": {"test_a.py": "a.mcap"}}
    written = json.loads(to_json(dataclasses.replace(result(), **data)))
    assert written["isolation"]["student_uids"] == [61003]
    assert written["memory"]["footprint_mb"] == 120.5 and written["timing"]["children"] == 1
    again = RunResult.from_dict(written)
    assert {key: getattr(again, key) for key in data} == data
    assert json.loads(to_json(again)) == written
