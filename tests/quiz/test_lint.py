"""``autograder quiz lint``: clean on the course, and each kind of problem as file:line."""

from __future__ import annotations

import re
from pathlib import Path

from click.testing import CliRunner

from autograder.cli.quiz import quiz_cli

REPO = Path(__file__).resolve().parents[2]


def _lint() -> tuple[int, list[str]]:
    result = CliRunner().invoke(quiz_cli, ["lint"])
    assert "Traceback" not in result.output
    return result.exit_code, result.output.strip().splitlines()


def _po(course: Path) -> Path:
    return course / "locales" / "ur" / "LC_MESSAGES" / "content.po"


def _set_msgstr(po: Path, context: str, new: str, fuzzy: bool = False) -> None:
    text = po.read_text()
    entry = rf'msgctxt "{re.escape(context)}"\nmsgid (?:"[^\n]*"\n)+'
    pattern = rf'(#, fuzzy\n)?({entry})msgstr (?:"[^\n]*"\n)+'
    flag = "#, fuzzy\n" if fuzzy else ""
    text, n = re.subn(pattern, lambda m: f'{flag}{m.group(2)}msgstr "{new}"\n', text)
    assert n == 1, context
    po.write_text(text)


def test_course_is_clean(course: Path) -> None:
    code, lines = _lint()
    assert code == 0, lines


def test_missing_translation_fails(course: Path) -> None:
    _set_msgstr(_po(course), "quiz:rclpy-part2:gil:text", "")
    code, lines = _lint()
    assert code == 1
    assert lines[0].startswith(str(course / "quizzes" / "part2-rclpy.yaml") + ":44: ur: ")
    assert "no translation of quiz:rclpy-part2:gil:text" in lines[0]
    assert lines[-1] == "Error: 1 problem found"


def test_fuzzy_translation_fails(course: Path) -> None:
    _set_msgstr(_po(course), "quiz:rclpy-part2:gil:text", "جی آئی ایل کیا ہے؟", fuzzy=True)
    code, lines = _lint()
    assert code == 1 and "is fuzzy" in lines[0]


def test_changed_code_or_placeholder_fails(course: Path) -> None:
    _set_msgstr(_po(course), "quiz:callback-groups:reentrant-meaning:text",
                "`ReentrantGroup` کس بات کی اجازت دیتا ہے؟")
    code, lines = _lint()
    assert code == 1
    assert "`ReentrantCallbackGroup` became `ReentrantGroup`" in lines[0]


def test_new_string_without_catalog_entry_fails(course: Path) -> None:
    quiz = course / "quizzes" / "part2-rclpy.yaml"
    quiz.write_text(quiz.read_text().replace(
        "What is the Global Interpreter Lock (GIL)?", "What does the GIL do?"))
    code, lines = _lint()
    assert code == 1 and ":44: ur: no translation" in lines[0]


def test_malformed_quiz_and_duplicate_ids_and_tolerance(course: Path) -> None:
    folder = course / "quizzes"
    (folder / "copy.yaml").write_text((folder / "part2-rclpy.yaml").read_text())
    timer = folder / "timer-synchronization.yaml"
    timer.write_text(timer.read_text().replace("tolerance: 0\n", "tolerance: 8\n"))
    (folder / "broken.yaml").write_text("id: broken\ntitle: [\n")
    code, lines = _lint()
    assert code == 1
    assert any(line.startswith(f"{folder / 'broken.yaml'}:3: YAML error") for line in lines)
    assert any("quiz id 'rclpy-part2' is also used by" in line for line in lines)
    assert any(re.search(r"timer-synchronization.yaml:\d+: "
                         r"questions\[calls-in-two-seconds\].tolerance", line) for line in lines)


def test_malformed_catalog_is_one_line_naming_it(course: Path) -> None:
    po = _po(course)
    po.write_text(po.read_text().replace('msgstr "', 'msgstr "\n"unterminated', 1) + 'msgid "x\n')
    code, lines = _lint()
    assert code == 1
    assert any(line.startswith(f"{po}:") and "malformed catalog" in line for line in lines)
    answers = course / "a.json"
    answers.write_text('{"quiz": "rclpy-part2", "answers": {}}')
    result = CliRunner().invoke(quiz_cli, ["score", "rclpy-part2", str(answers), "--lang", "ur"])
    assert result.exit_code == 2 and "Traceback" not in result.output
    assert len(result.output.strip().splitlines()) == 1 and str(po) in result.output
