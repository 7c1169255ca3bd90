"""The Babel extractors of course content: every translatable string of a quiz, and an
exercise's title and summary, each with a gettext context made of ids and the real line
of the string in its YAML file; Babel finds them by module path (babel.cfg)."""

from __future__ import annotations

import io
from pathlib import Path

from quiz_course import QUIZ_COURSE

from autograder.quiz.extract import extract_exercise, extract_quiz

ALL_TITLE = "Part 2 quiz: Python and ROS 2 with rclpy"


def _extract(func: object, path: Path) -> list[tuple]:
    with path.open("rb") as fh:
        return list(func(fh, {}, (), {}))  # type: ignore[operator]


def test_quiz_extractor_gives_contexts_and_real_lines() -> None:
    path = QUIZ_COURSE / "quizzes" / "part2-rclpy.yaml"
    found = {msg[1]: (line, msg[0]) for line, func, msg, _c in _extract(extract_quiz, path)}
    lines = path.read_text().splitlines()
    line, ctx = found["What is the Global Interpreter Lock (GIL)?"]
    assert ctx == "quiz:rclpy-part2:gil:text"
    assert "What is the Global Interpreter Lock" in lines[line - 1]
    assert found["None of the above"][1] == "quiz:rclpy-part2:shared-resources:options.none"
    # Code-only options are not translated: nothing to extract.
    assert "`ReentrantCallbackGroup`" not in found
    assert all(func == "pgettext" for _l, func, _m, _c in _extract(extract_quiz, path))


def test_exercise_extractor(tmp_path: Path) -> None:
    path = tmp_path / "assignments" / "timers" / "exercise.yaml"
    path.parent.mkdir(parents=True)
    path.write_text("id: timers\nkind: exercise\ntitle: Timers\nsummary: Two timers.\n")
    found = [(line, msg) for line, _f, msg, _c in _extract(extract_exercise, path)]
    assert found == [(3, ("exercise:timers:title", "Timers")),
                     (4, ("exercise:timers:summary", "Two timers."))]


def test_babel_accepts_our_extractor_by_module_path() -> None:
    # babel.cfg names the extractor by module path, so pybabel works from a checkout.
    from babel.messages.extract import extract

    source = QUIZ_COURSE / "quizzes" / "part2-rclpy.yaml"
    messages = list(extract("autograder.quiz.extract:extract_quiz",
                            io.BytesIO(source.read_bytes())))
    lineno, message, _comments, context = messages[0]
    assert (lineno, context, message) == (3, "quiz:rclpy-part2:title", ALL_TITLE)


def test_an_exercise_without_an_id_is_named_by_its_folder_and_blank_fields_are_skipped(
        tmp_path: Path) -> None:
    path = tmp_path / "assignments" / "drive" / "exercise.yaml"
    path.parent.mkdir(parents=True)
    path.write_text("kind: exercise\nsummary: '  '\ntitle: Drive\n")
    found = [(line, func, msg, comments)
             for line, func, msg, comments in _extract(extract_exercise, path)]
    assert found == [(3, "pgettext", ("exercise:drive:title", "Drive"), ["exercise title"])]
