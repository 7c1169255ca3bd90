"""grade-batch --jobs auto never changes a verdict: the proof's checks (references full,
starter below the pass mark, each known-bad variant losing exactly its tests) hold for a
batch graded at the concurrency auto chooses, for the clock-bound exercise whose verdicts
hang most on timing (timer_sync). Every exercise's own proof runs two gradings at a time
(tests/proving.py), and the mini course's batch compares auto with one by one."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import pytest
from proving import Proof, diagnosis, explain, failed_tests

from autograder.core.exercise import find_exercise
from autograder.core.results import RunResult

pytestmark = pytest.mark.slow

REFERENCES = 3


@pytest.fixture(scope="module", params=["timer_sync"])
def batch(request, tmp_path_factory) -> tuple[Proof, dict[str, RunResult], int]:
    """Every submission of the exercise's proof graded by one `grade-batch --jobs auto`:
    the proof, each student's result, and the concurrency auto chose."""
    proof = Proof(request.param, repeats=REFERENCES)
    exercise = find_exercise(proof.exercise)
    root = tmp_path_factory.mktemp(proof.exercise)
    programs = {f"reference{i}": exercise.solution.read_text(encoding="utf-8")
                for i in range(REFERENCES)}
    programs["starter"] = exercise.starter.read_text(encoding="utf-8")
    programs |= {name: v.program(exercise) for name, v in proof.variants.items()}
    for name, program in programs.items():
        (root / "submissions" / name).mkdir(parents=True)
        (root / "submissions" / name / exercise.file).write_text(program, encoding="utf-8")
    proc = subprocess.run([sys.executable, "-m", "autograder.cli", "grade-batch",
                           proof.exercise, str(root / "submissions"), "--jobs", "auto",
                           "--csv", str(root / "book.csv"), "--out", str(root / "out")],
                          capture_output=True, text=True, timeout=1800)
    assert proc.returncode == 0, proc.stderr
    chosen = re.search(r"--jobs auto: (\d+) grading", proc.stderr)
    assert chosen, proc.stderr
    results = {name: RunResult.from_dict(json.loads(
        (root / "out" / name / "results.json").read_text(encoding="utf-8")))
        for name in programs}
    return proof, results, int(chosen[1])


def test_references_score_full_marks(batch) -> None:
    _proof, results, jobs = batch
    for i in range(REFERENCES):
        result = results[f"reference{i}"]
        assert result.grader_error is None, explain(jobs=jobs, **diagnosis(result))
        assert result.score == result.max_score, explain(jobs=jobs, **diagnosis(result))


def test_starter_is_below_the_pass_mark(batch) -> None:
    _proof, results, jobs = batch
    assert results["starter"].grader_error is None, explain(**diagnosis(results["starter"]))
    assert not results["starter"].passed, jobs


def test_variants_lose_exactly_what_their_proof_says(batch) -> None:
    proof, results, jobs = batch
    wrong = {}
    for name, variant in proof.variants.items():
        result = results[name]
        lost = failed_tests(result)
        if result.grader_error is not None or (
                variant.kind == "correct" and result.score != result.max_score):
            wrong[name] = diagnosis(result)
        elif variant.kind != "correct" and lost != variant.loses:
            wrong[name] = {"expected": sorted(variant.loses), **diagnosis(result)}
    assert not wrong, explain(jobs=jobs, wrong=wrong)
