"""The quizzes the platform's quiz tests read: a frozen copy of a course's, so that editing
quizzes/ never breaks a platform test (tests/fixtures/quiz_course/README.md)."""

from __future__ import annotations

from pathlib import Path

QUIZ_COURSE = Path(__file__).resolve().parent / "fixtures" / "quiz_course"
