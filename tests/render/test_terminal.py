"""Words a student understands: whether their run was contained, in a sentence (the
technical line for instructors with --verbose); a node that printed nothing told so; a
warning when `sim drive` bypasses the student's node."""

from __future__ import annotations

from fractions import Fraction
from typing import Any

import pytest
from click.testing import CliRunner

import sim.cli
from autograder.cli import main
from autograder.core.results import Containment, RunResult, TestResult
from autograder.render.html import to_html
from autograder.render.terminal import to_terminal
from autograder.sandbox.isolation import Isolation

BOUNDS = {"cgroup": None, "processes": None, "memory": None}


def _result(**fields: Any) -> RunResult:
    test = TestResult(name="test_clamps", label="Clamps", score=Fraction(1),
                      max_score=Fraction(1), status="passed")
    return RunResult(kind="exercise", id="parameter_validation", title="Governor",
                     tests=(test,), **fields)


def _isolation(mode: str) -> Containment:
    reason = "" if mode == "strict" else "the grader does not run as root"
    return Containment.from_dict(
        {**Isolation(mode, reason).to_dict(), "bounds": BOUNDS})  # type: ignore[arg-type]


@pytest.mark.parametrize(("mode", "sentence"), [
    ("strict", "Your program ran contained, as a user of its own, so this grade stands for "
               "what your node did and nothing else."),
    ("user", "Your program ran contained, as a user of its own, so this grade stands for "
             "what your node did and nothing else."),
    ("basic", "Your program was not contained (it ran as the grader's own user), so it could "
              "have changed this result: this grade is not official."),
])
def test_a_student_reads_one_sentence_on_containment(mode: str, sentence: str) -> None:
    text = to_terminal(_result(isolation=_isolation(mode)))
    assert text.splitlines()[-1] == sentence
    assert "bounded by" not in text and "cgroup" not in text


def test_an_instructor_reads_the_technical_line_with_verbose() -> None:
    text = to_terminal(_result(isolation=_isolation("basic")), verbose=True)
    assert "Isolation: basic, the grader does not run as root" in text
    assert "processes bounded by nothing" in text


def test_verbose_is_an_option_of_check_and_grade() -> None:
    for command in ("check", "grade"):
        result = CliRunner().invoke(main, [command, "--help"])
        assert "--verbose" in result.output


def test_a_silent_node_is_told_so_not_shown_an_empty_box() -> None:
    html = to_html(_result(silent=True))
    assert "Your node printed nothing: no output and no log line in any test." in html
    assert "The end of your node&#39;s log" not in html


def test_a_blank_log_tail_shows_no_box() -> None:
    html = to_html(_result(log_tail="\n\n\n"))
    assert "The end of your node&#39;s log" not in html
    assert "printed nothing" not in html  # not known to be silent: nothing claimed


@pytest.mark.parametrize(("args", "warned"), [
    ([], True), (["--topic", "/cmd_vel"], False), (["--topic", "/agent/cmd_vel"], False)])
def test_sim_drive_warns_when_it_bypasses_the_students_node(
        monkeypatch: pytest.MonkeyPatch, args: list[str], warned: bool) -> None:
    driven: list[str] = []
    monkeypatch.setattr(sim.cli, "drive", lambda topic, *a, **k: driven.append(topic))
    result = CliRunner().invoke(main, ["sim", "drive", "--linear", "0.2", *args])
    assert result.exit_code == 0, result.output
    assert driven == [args[1] if args else "/cmd_vel"]
    assert ("Warning: without --topic this drives /cmd_vel" in result.output) == warned
