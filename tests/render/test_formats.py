"""The renderers are pure functions of a RunResult: what every format says alike (the core
tests, a partial run, hidden messages, the terminal and HTML pages); each format's own
shape is in its test file (test_gradescope.py, test_junit.py, test_jsonfile.py, ...)."""

from __future__ import annotations

import dataclasses
import json
import re
import xml.etree.ElementTree as ET
from fractions import Fraction

import pytest
from graded_result import SECRET
from graded_result import graded_result as result

from autograder.core.results import (
    NotRun,
    RunResult,
    TestResult,
)
from autograder.i18n import set_language
from autograder.render.gradescope import to_gradescope_dict
from autograder.render.html import to_html
from autograder.render.jsonfile import to_json
from autograder.render.junit import to_junit
from autograder.render.terminal import to_terminal


def test_terminal_has_a_line_per_test_and_the_verdict():
    text = to_terminal(result())
    for label in ("The node starts", "cmd_vel keeps 10 Hz", "Refuses bad values"):
        assert label in text
    assert "Score: 2.5/7" in text and "not passed" in text


def test_terminal_says_each_thing_once():
    """A line per test, then each failure once: its message and its hint; a hidden test's
    message and hint stay hidden, as in every other format."""
    text = to_terminal(result())
    for label in ("The node starts", "Refuses bad values", "Exits on a bad override"):
        assert len(re.findall(rf"^ . +[\d.]+/\d  {label}$", text, re.M)) == 1, text
    assert text.count("cmd_vel keeps 10 Hz") == 2  # its line, and its failure's heading
    assert text.count("`cmd_vel` came at 3.1 Hz") == 1
    assert text.count("Hint: Is the planner in its own callback group?") == 1
    assert text.count("covered half the way") == 1
    assert SECRET not in text


def test_failures_with_the_same_hint_stand_together_under_it_once():
    """timer_sync's starter fails four tests for one cause: its hint is said once."""
    planner = "The planner blocks for 2 s.\nGive it a callback group of its own."

    def failed(name: str, message: str, hint: str) -> TestResult:
        return TestResult(name, f"{name} label", Fraction(0), Fraction(1), "failed",
                          message=message, hint=hint)

    run = RunResult("exercise", "timer_sync", "T", (
        failed("test_rate", "cmd_vel stopped", planner),
        failed("test_status", "no status", "Create a 1 s timer."),
        failed("test_plan", "no plan", planner)))
    text = to_terminal(run)
    assert text.count("The planner blocks for 2 s.") == 1
    assert ("✘ test_rate label\n    cmd_vel stopped\n✘ test_plan label\n    no plan\n"
            "    Hint for the 2 failures above: The planner blocks for 2 s.\n"
            "    Give it a callback group of its own.\n\n✘ test_status label\n    no status\n"
            "    Hint: Create a 1 s timer.") in text


def test_terminal_leaves_out_the_lines_already_shown():
    shown = {"test_starts", "test_rate"}
    text = to_terminal(result(), shown=shown, with_heading=False)
    assert not text.startswith("timer_sync")
    assert " ✔   1/1  The node starts" not in text
    assert " ✘   0/2  cmd_vel keeps 10 Hz" not in text
    assert " ✘   0/2  Refuses bad values" in text  # not shown yet: printed here
    assert text.count("Hint: Is the planner in its own callback group?") == 1


@pytest.mark.parametrize(("not_run", "says"), [
    (NotRun(8, Fraction(9)), "The grade also runs 8 hidden tests (9 points)."),
    (NotRun(1, Fraction(1)), "The grade also runs 1 hidden test (1 point)."),
    (NotRun(None, Fraction(3, 2)), "The grade also runs hidden tests (1.5 points)."),
    (NotRun(), "The grade also runs hidden tests.")], ids=["both", "one", "points", "unknown"])
def test_a_partial_run_says_what_it_proved_and_gives_no_verdict(not_run, says):
    partial = dataclasses.replace(result(), not_run=not_run)
    text = to_terminal(partial)
    assert "Public tests: 2.5/7 (36%)." in text and says in text
    assert "Score:" not in text and "passed" not in text
    data = json.loads(to_json(partial))
    assert data["passed"] is None and data["not_run"] == not_run.to_dict()
    assert RunResult.from_dict(data).not_run == not_run
    props = {p.get("name"): p.get("value")
             for p in ET.fromstring(to_junit(partial).encode()).find("testsuite/properties")}
    assert "passed" not in props and props["complete"] == "false"
    page = to_html(partial)
    verdict = re.search(r'id="verdict">(.*?)</div>\s*<p class="pass-mark">(.*?)</p>', page, re.S)
    assert verdict is not None and "Public tests: 2.5/7" in verdict[1] and says in verdict[2]
    assert "passed" not in verdict[0]


def test_terminal_says_when_the_grader_failed():
    assert "The autograder failed, tell your instructor." in to_terminal(result(grader_error="x"))


def test_html_report_escapes_hides_and_draws():
    page = to_html(result())
    assert '<html lang="en" dir="ltr">' in page
    assert "<script>alert(1)</script>" not in page and "&lt;script&gt;" in page
    assert SECRET not in page
    assert '<code dir="ltr">cmd_vel</code>' in page
    assert 'class="chart"' in page and 'class="limit"' in page
    assert "[INFO] hi" in page


def test_urdu_html_report_is_right_to_left():
    set_language("ur")
    page = to_html(result(lang="ur"))
    assert '<html lang="ur" dir="rtl">' in page
    assert "Noto Nastaliq Urdu" in page
    assert '<code dir="ltr">cmd_vel</code>' in page
    assert '<pre dir="ltr">' in page


def core_missed(lang: str = "en") -> RunResult:
    """At the pass mark on points (9/10), but its one core test failed."""
    tests = (
        TestResult("test_refuses", "Refuses bad values", Fraction(0), Fraction(1), "failed",
                   message="accepted 3.0", core=True),
        TestResult("test_clamps", "Clamps linear.x", Fraction(9), Fraction(9), "passed",
                   core=True),
    )
    return RunResult("exercise", "parameter_validation", "A governor", tests, lang=lang)


@pytest.mark.parametrize("lang,headline,core_mark", [
    ("en", "Not passed: this core test failed", "Refuses bad values (core)"),
    ("ur", "کامیاب نہیں: یہ بنیادی test ناکام ہوا", "Refuses bad values (بنیادی)"),
])
def test_every_format_names_the_core_test_that_kept_it_from_passing(lang, headline,
                                                                     core_mark):
    set_language(lang)
    run = core_missed(lang)
    assert run.fraction >= run.pass_mark and not run.passed
    data = json.loads(to_json(run))
    assert (data["passed"], data["core_missed"]) == (False, ["test_refuses"])
    assert [t["core"] for t in data["tests"]] == [True, True]
    assert RunResult.from_dict(data).core_missed[0].name == "test_refuses"
    terminal = to_terminal(run)
    assert headline in terminal and core_mark in terminal
    # The core test that failed is named after the verdict; the one that passed is not.
    after = terminal[terminal.index(headline):]
    assert "Refuses bad values" in after and "Clamps linear.x" not in after
    gradescope = to_gradescope_dict(run)
    assert headline in gradescope["output"] and "- Refuses bad values" in gradescope["output"]
    assert gradescope["tests"][0]["name"] == core_mark
    suite = ET.fromstring(to_junit(run)).find("testsuite")
    properties = {p.get("name"): p.get("value") for p in suite.find("properties")}
    assert (properties["passed"], properties["core_missed"]) == ("false", "test_refuses")
    assert suite.find("testcase/failure").text.endswith(
        "whatever the points." if lang == "en" else "کامیاب نہیں ہوتی۔")
    page = to_html(run)
    box = page[page.index('id="core-missed"'):]
    box = re.sub(r"<[^>]+>", "", box[:box.index("</div>")])  # the words, without bidi tags
    assert headline in box and "Refuses bad values" in box


def test_a_grader_failure_is_not_blamed_on_the_core_tests():
    run = dataclasses.replace(core_missed(), grader_error="the autograder failed")
    assert not run.passed
    assert "core test" not in to_terminal(run) and 'id="core-missed"' not in to_html(run)
    assert "core test" not in to_gradescope_dict(run)["output"]


def test_a_grading_with_every_core_test_passed_says_nothing_of_them():
    run = core_missed()
    run = dataclasses.replace(run, tests=(dataclasses.replace(run.tests[0], core=False),
                                          run.tests[1]))
    assert run.passed and not run.core_missed
    assert "core test" not in to_terminal(run) and 'id="core-missed"' not in to_html(run)
    assert json.loads(to_json(run))["core_missed"] == []
