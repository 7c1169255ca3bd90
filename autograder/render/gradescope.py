"""Gradescope's ``results.json`` (the autograder specification's fields and values)."""

from __future__ import annotations

import json
from typing import Any

from autograder.core.results import RunResult, TestResult, number
from autograder.i18n import _
from autograder.render import OutputFormat
from autograder.render.verdict import core_label, core_lines

# Gradescope's visibility values; our "hidden" tests follow the exercise's setting.
_VISIBILITY = {"visible": "visible", "hidden": "hidden", "after_published": "after_published"}


def _output(test: TestResult) -> str:
    parts = [test.student_message]
    if test.student_hint:
        parts.append(_("Hint: {hint}").format(hint=test.student_hint))
    return "\n".join(p for p in parts if p)


def to_gradescope_dict(result: RunResult) -> dict[str, Any]:
    summary = _("Score: {score}/{max_score}. Pass mark: {mark}%.").format(
        score=number(result.score), max_score=number(result.max_score),
        mark=number(result.pass_mark * 100))
    if result.grader_error:
        summary += "\n" + _("The autograder failed, tell your instructor.")
    elif result.core_missed:
        summary += "\n" + "\n".join(core_lines(result))
    return {
        "score": number(result.score),
        "execution_time": round(result.execution_time),
        "output": summary,
        "output_format": "text",
        "stdout_visibility": "hidden",
        "tests": [
            {
                "name": core_label(test),
                "name_format": "text",
                "number": str(index),
                "score": number(test.score),
                "max_score": number(test.max_score),
                "status": "passed" if test.passed else "failed",
                "output": _output(test),
                "output_format": "text",
                "visibility": _VISIBILITY[test.visibility],
            }
            for index, test in enumerate(result.tests, start=1)
        ],
    }


def to_gradescope(result: RunResult) -> str:
    return json.dumps(to_gradescope_dict(result), ensure_ascii=False, indent=2) + "\n"


FORMAT = OutputFormat(
    "gradescope", "Write Gradescope's results.json to this file.",
    lambda result, _folder: to_gradescope(result), batch_file="gradescope.json", order=30)
