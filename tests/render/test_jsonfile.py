"""The JSON results file (autograder.render.jsonfile): the results model's dictionary as
UTF-8 text, indented, ending in a newline; its shape is tests/core/test_results.py's."""

from __future__ import annotations

import json
from fractions import Fraction
from pathlib import Path

from autograder.core.results import RunResult, TestResult
from autograder.render.jsonfile import FORMAT, to_json


def result() -> RunResult:
    test = TestResult("test_speaks", "بولتا ہے", Fraction(1), Fraction(1), "passed")
    return RunResult("exercise", "shout", "آواز", (test,), lang="ur")


def test_the_file_is_readable_utf8_indented_with_a_last_newline() -> None:
    text = to_json(result())
    assert "آواز" in text and "\\u" not in text  # Urdu as itself, not escaped
    assert text.endswith("}\n") and text.startswith('{\n  "exercise": "shout",\n')
    assert json.loads(text) == result().to_dict()


def test_the_format_writes_results_json_in_a_batch() -> None:
    assert FORMAT.batch_file == "results.json"
    assert FORMAT.name == "results"
    assert FORMAT.render(result(), Path(".")) == to_json(result())
