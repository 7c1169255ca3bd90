"""The fixtures the quiz tests share."""

from __future__ import annotations

import shutil
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from quiz_course import QUIZ_COURSE

from autograder.i18n import translations
from autograder.quiz.catalog import load_all
from autograder.quiz.server import QuizServer


@pytest.fixture
def server() -> Iterator[QuizServer]:
    """``quiz serve`` of the frozen quiz course on a free port, in a thread."""
    srv = QuizServer(load_all(QUIZ_COURSE), port=0)
    # serve_forever looks for shutdown() between requests every poll_interval (0.5 s by
    # default): each test's teardown would wait that long for nothing
    thread = threading.Thread(target=srv.serve_forever, kwargs={"poll_interval": 0.02},
                              daemon=True)
    thread.start()
    yield srv
    srv.shutdown()
    srv.server_close()
    thread.join(timeout=5)


@pytest.fixture
def course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A copy of the frozen course's quizzes and catalogs that a test may break, as the
    course (its catalogs the ones read)."""
    shutil.copytree(QUIZ_COURSE / "quizzes", tmp_path / "quizzes")
    shutil.copytree(QUIZ_COURSE / "locales", tmp_path / "locales")
    monkeypatch.setenv("AUTOGRADER_COURSE", str(tmp_path))
    monkeypatch.setenv("AUTOGRADER_LOCALES", str(tmp_path / "locales"))
    translations.cache_clear()
    yield tmp_path
    translations.cache_clear()
