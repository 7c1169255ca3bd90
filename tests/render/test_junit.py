"""JUnit XML (autograder.render.junit): a suite CI tools parse back, a failure per failed
test, the grader's error where it failed."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from fractions import Fraction

from graded_result import graded_result as result

from autograder.core.results import (
    RunResult,
    TestResult,
)
from autograder.render.junit import to_junit


def test_junit_parses_back():
    root = ET.fromstring(to_junit(result()).encode())
    suite = root.find("testsuite")
    assert suite is not None
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors")) == ("5", "3", "0")
    cases = suite.findall("testcase")
    assert [c.get("name") for c in cases] == ["test_starts", "test_rate", "test_hidden",
                                               "test_hidden2", "test_partial"]
    failure = cases[1].find("failure")
    assert failure is not None and "3.1 Hz" in failure.get("message")
    props = {p.get("name"): p.get("value") for p in suite.find("properties")}
    assert props["score"] == "2.5" and props["passed"] == "false"


def test_junit_reports_a_grader_error():
    root = ET.fromstring(to_junit(result(grader_error="boom")).encode())
    assert root.find("testsuite/system-err") is not None


def test_junit_marks_a_cut_first_line():
    test = TestResult("test_dies", "It lives on", Fraction(0), Fraction(1), "failed",
                      message="It ended (exit status 1). Its last lines:\nValueError: x")
    one = RunResult("exercise", "x", "X", (test,))
    failure = ET.fromstring(to_junit(one).encode()).find("testsuite/testcase/failure")
    assert failure.get("message") == "It ended (exit status 1). Its last lines: …"
    assert "ValueError: x" in failure.text
