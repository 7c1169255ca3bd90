"""The CLI turns each exception family of a plain command function into its exit status,
in one place: bad input 2, a malformed content file 2, our own failure 3."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner

from autograder.cli import main
from autograder.commands import grade
from autograder.core.errors import ContentError, GraderError, UsageError


@pytest.mark.parametrize(("raised", "status", "line"), [
    (UsageError("mywork/node.py not found"), 2, "Error: mywork/node.py not found"),
    (ContentError(Path("exercise.yaml"), "must be a number", 3, "points"), 2,
     "Error: exercise.yaml:3: points: must be a number"),
    (GraderError("the simulator did not start"), 3, "Error: the simulator did not start"),
], ids=["usage", "content", "grader"])
def test_each_family_has_its_exit_status(monkeypatch: pytest.MonkeyPatch, raised: Exception,
                                         status: int, line: str) -> None:
    def fail(*args: Any, **kwargs: Any) -> None:
        raise raised

    monkeypatch.setattr(grade, "check_or_grade", fail)
    result = CliRunner().invoke(main, ["check", "parameter_validation", "node.py",
                                       "--lang", "en"])
    assert result.exit_code == status
    assert line in result.output
    assert "Traceback" not in result.output


def test_an_unknown_exercise_is_bad_input() -> None:
    result = CliRunner().invoke(main, ["check", "no_such_exercise", "node.py", "--lang", "en"])
    assert result.exit_code == 2 and "no_such_exercise" in result.output
