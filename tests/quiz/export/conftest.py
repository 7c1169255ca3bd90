"""The fixtures of the LMS export tests."""

from __future__ import annotations

import pytest
from quiz_exports import EDGE

from autograder.quiz.model import QuizFile, load_quiz


@pytest.fixture(scope="module")
def edge(tmp_path_factory: pytest.TempPathFactory) -> QuizFile:
    path = tmp_path_factory.mktemp("edge") / "edge.yaml"
    path.write_text(EDGE)
    return load_quiz(path)

