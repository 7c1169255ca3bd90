"""Gradescope's results.json (autograder.render.gradescope): its fields and visibility
values, and nothing a hidden test does not reveal."""

from __future__ import annotations

import json

from graded_result import SECRET
from graded_result import graded_result as result

from autograder.render.gradescope import to_gradescope, to_gradescope_dict


def test_gradescope_fields_and_visibility_values():
    data = to_gradescope_dict(result())
    assert json.loads(to_gradescope(result())) == data
    assert data["score"] == 2.5 and data["execution_time"] == 12
    assert data["stdout_visibility"] in {"hidden", "visible", "after_due_date",
                                         "after_published"}
    assert isinstance(data["output"], str)
    for test in data["tests"]:
        assert {"name", "score", "max_score", "status", "output", "visibility"} <= set(test)
        assert test["status"] in {"passed", "failed"}
        assert test["visibility"] in {"visible", "hidden", "after_due_date", "after_published"}
    assert [t["visibility"] for t in data["tests"]] == [
        "visible", "visible", "after_published", "hidden", "visible"]
    assert sum(t["score"] for t in data["tests"]) == data["score"]


def test_gradescope_hides_what_a_hidden_test_does_not_reveal():
    text = to_gradescope(result())
    assert SECRET not in text
    assert "Is the planner in its own callback group?" in text
