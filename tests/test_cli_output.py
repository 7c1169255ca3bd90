"""What a student reads after ``check`` and ``grade``: the real output of the command, in
English and Urdu, on parameter_validation's starter and reference (runs shared with the
other modules that read them: tests/student_runs.py).

Each test's line appears once, each failure's message once and each hint once (failures
that share one stand together under it), the student's file is named as they gave it
(never the grader's throwaway copy), ``check`` says what it proved and never "passed", and
on a terminal the running test is redrawn in place while each test's final line is still
printed once. The runs are real ones (the CLI in a process of
its own, grading in the simulator), two at a time, as the exercises' proofs run.
"""

from __future__ import annotations

import os
import pty
import re
import subprocess
import sys
import unicodedata
from collections import Counter
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
from babel.numbers import format_percent
from student_runs import TEST_LINE, Run, Spec, StudentRuns, env

from autograder.i18n import translations

pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parent.parent
EXERCISE = "parameter_validation"
STARTER = f"assignments/{EXERCISE}/starter/velocity_governor.py"
REFERENCE = f"assignments/{EXERCISE}/solution"
RUNS = {
    "check-starter-en": Spec("check", EXERCISE, STARTER, "en"),
    "check-starter-ur": Spec("check", EXERCISE, STARTER, "ur"),
    "check-reference-en": Spec("check", EXERCISE, REFERENCE, "en"),
    "grade-starter-en": Spec("grade", EXERCISE, STARTER, "en"),
    "grade-reference-ur": Spec("grade", EXERCISE, REFERENCE, "ur"),
}


def _marked(test: dict, lang: str) -> str:
    """A test's label as its line shows it: with the core mark of its language."""
    from autograder.i18n.text import using_language
    from autograder.render.verdict import core_label

    with using_language(lang):
        return core_label(SimpleNamespace(label=test["label"], core=test["core"]))


def _run_on_a_terminal() -> str:
    """``check`` on the starter with its stdout on a pseudo-terminal: the raw text."""
    leader, follower = pty.openpty()
    process = subprocess.Popen(
        [sys.executable, "-m", "autograder.cli", "check", EXERCISE, STARTER, "--lang", "en"],
        cwd=REPO, env={**env(), "COLUMNS": "200"}, stdout=follower,
        stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL)
    os.close(follower)
    chunks = []
    while True:
        try:
            chunk = os.read(leader, 65536)
        except OSError:  # the terminal closed: the command ended
            break
        if not chunk:
            break
        chunks.append(chunk)
    process.wait(timeout=600)
    os.close(leader)
    return b"".join(chunks).decode("utf-8", "replace")


@pytest.fixture(scope="module")
def runs(student_runs: StudentRuns) -> dict[str, Any]:
    on_terminal = student_runs.submit("check-starter-en-on-a-terminal", _run_on_a_terminal)
    made = dict(zip(RUNS, student_runs.get(*RUNS.values()), strict=True))
    return {**made, "terminal": on_terminal.result()}


@pytest.mark.parametrize("name", list(RUNS))
def test_each_test_line_and_each_failure_once(runs, name):
    run: Run = runs[name]
    assert run.code == 0, run.stderr
    tests = run.results["tests"]
    assert run.results["grader_error"] is None
    assert run.test_lines() == Counter(_marked(t, run.results["lang"]) for t in tests), \
        run.stdout
    revealed = [t for t in tests if t["status"] == "failed" and t["reveal"] == "message"]
    for hint in {t["hint"].splitlines()[0] for t in revealed if t["hint"]}:
        assert run.count(hint) == 1, (hint, run.stdout)  # tests that share it: once too
    for test in revealed:
        first = test["message"].splitlines()[0]
        assert run.count(first) == sum(t["message"].startswith(first) for t in revealed)
    for test in tests:  # what a hidden test does not reveal stays out of the terminal
        if test["reveal"] != "message" and test["message"]:
            assert test["message"].splitlines()[0] not in run.stdout
    assert "/tmp/autograder-" not in run.stdout and "/student-" not in run.stdout
    assert "\x1b[" not in run.stdout  # a pipe gets plain lines


def test_the_starter_is_graded_below_the_pass_mark_with_hints(runs):
    run: Run = runs["grade-starter-en"]
    assert re.search(r"^Score: [\d.]+/13 \(\d+%\), not passed \(pass mark 70%\)$",
                     run.stdout, re.M)
    assert run.count("Hint: `linear.x=3.0` was passed on unclamped: clamp it with "
                     "`max(-limit, min(limit, value))`, where limit is max_linear_speed.") == 1
    assert run.results["passed"] is False


@pytest.mark.parametrize("name", ["check-starter-en", "check-reference-en",
                                  "check-starter-ur"])
def test_check_says_what_it_proved_and_never_passed(runs, name):
    run: Run = runs[name]
    public = len(run.results["tests"])
    hidden = run.results["not_run"]
    assert hidden["tests"] > 0 and public + hidden["tests"] == 11
    assert run.results["max_score"] + hidden["points"] == 13
    assert run.results["passed"] is None
    ur = translations("ur" if name.endswith("-ur") else "en")
    prefix = ur.gettext("Public tests: {score}/{max_score} ({percent}).").split("{")[0]
    assert run.count(f"{prefix}{run.results['score']}/{run.results['max_score']} ") == 1
    says = ur.ngettext("The grade also runs {count} hidden test ({points}).",
                       "The grade also runs {count} hidden tests ({points}).",
                       hidden["tests"]).split("{")[0]
    assert run.count(says) == 1
    verdict = ur.gettext("Score: {score}/{max_score} ({percent}), {verdict} (pass mark {mark})")
    assert verdict.split("{")[0] not in run.stdout
    if name == "check-reference-en":
        assert "Public tests: 5/5 (100%).\nThe grade also runs 6 hidden tests (8 points)." \
            in run.stdout


def _first_strong(line: str) -> str | None:
    return next((kind for kind in map(unicodedata.bidirectional, line)
                 if kind in ("L", "R", "AL")), None)


def test_grade_of_the_reference_passes_in_urdu(runs):
    run: Run = runs["grade-reference-ur"]
    assert run.results["passed"] is True and run.results["lang"] == "ur"
    ur = translations("ur")
    score = ur.gettext("Score: {score}/{max_score} ({percent}), {verdict} (pass mark {mark})")
    assert run.count(score.format(
        score=13, max_score=13, percent=format_percent(1, locale="ur"),
        verdict=ur.gettext("passed"), mark=format_percent(0.7, locale="ur"))) == 1
    # Each Urdu line reads right to left in a terminal that lays out bidi text.
    for line in run.stdout.splitlines():
        if any(unicodedata.bidirectional(c) == "AL" for c in line):
            assert _first_strong(line) != "L", line


def test_on_a_terminal_the_running_test_is_redrawn_and_each_line_printed_once(runs):
    raw: str = runs["terminal"]
    assert "\r\x1b[2K" in raw  # the running test, drawn in place
    # What stays on the screen: each redrawn stretch replaced by what followed it.
    screen = [re.sub(r"\x1b\[[0-9;]*m", "", line.rsplit("\r\x1b[2K", 1)[-1])
              for line in raw.replace("\r\n", "\n").split("\n")]
    finals = Counter(m[1] for m in map(TEST_LINE.match, screen) if m)
    assert len(finals) == 5 and set(finals.values()) == {1}, screen
    assert not any(line.startswith(" … ") for line in screen)  # nothing left half-drawn
