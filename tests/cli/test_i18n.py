"""``autograder i18n``: each command says what it wrote, relative to the working folder;
``--lang`` takes the translated languages only; a malformed catalog or content file is one
line and exit status 2; ``check`` ends with a success line or the problems and status 1.
(What extraction, update and compilation write: tests/i18n/test_tools.py.)"""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest
from click.testing import CliRunner
from quiz_course import QUIZ_COURSE

from autograder.cli.i18n import i18n_cli
from autograder.i18n import translations

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture
def course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A small course, the working folder: one quiz, one exercise, one platform module."""
    shutil.copy(REPO / "babel.cfg", tmp_path / "babel.cfg")
    (tmp_path / "quizzes").mkdir()
    shutil.copy(QUIZ_COURSE / "quizzes" / "part2-rclpy.yaml", tmp_path / "quizzes")
    (tmp_path / "assignments" / "timers").mkdir(parents=True)
    (tmp_path / "assignments" / "timers" / "exercise.yaml").write_text(
        "id: timers\ntitle: Timers\nsummary: Two timers.\n")
    (tmp_path / "autograder").mkdir()
    (tmp_path / "autograder" / "mod.py").write_text(
        "from autograder.i18n import _\nLABEL = _('Lazy label')\n")
    monkeypatch.setenv("AUTOGRADER_COURSE", str(tmp_path))
    monkeypatch.setenv("AUTOGRADER_LOCALES", str(tmp_path / "locales"))
    monkeypatch.chdir(tmp_path)
    translations.cache_clear()
    yield tmp_path
    translations.cache_clear()


def _run(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(i18n_cli, list(args))
    assert "Traceback" not in result.output, result.output
    return result.exit_code, result.output


def test_each_command_says_what_it_wrote(course: Path) -> None:
    assert _run("extract") == (0, "wrote locales/messages.pot\nwrote locales/content.pot\n")
    code, output = _run("update", "--lang", "ur")
    assert code == 0
    assert output.splitlines() == ["updated locales/ur/LC_MESSAGES/content.po",
                                   "updated locales/ur/LC_MESSAGES/messages.po"]
    code, output = _run("compile")
    assert code == 0
    assert output.splitlines() == ["compiled locales/ur/LC_MESSAGES/content.mo",
                                   "compiled locales/ur/LC_MESSAGES/messages.mo"]


def test_check_ends_with_the_problems_or_a_success_line(course: Path) -> None:
    _run("extract")
    _run("update")
    code, output = _run("check", "--lang", "ur")
    assert code == 1
    assert "ur: no translation of 'Lazy label'" in output
    assert "All catalogs are complete." not in output
    assert output.strip().splitlines()[-1].startswith("Error: ")
    assert output.strip().splitlines()[-1].endswith("problems found")


def test_check_of_complete_catalogs_says_so(monkeypatch: pytest.MonkeyPatch) -> None:
    """The project's own course and catalogs are complete."""
    monkeypatch.setenv("AUTOGRADER_COURSE", str(REPO))
    monkeypatch.setenv("AUTOGRADER_LOCALES", str(REPO / "locales"))
    translations.cache_clear()
    try:
        assert _run("check") == (0, "All catalogs are complete.\n")
    finally:
        translations.cache_clear()


def test_only_translated_languages_are_taken(course: Path) -> None:
    code, output = _run("update", "--lang", "en")
    assert code == 2 and "Invalid value for '--lang'" in output
    assert not (course / "locales" / "en").exists()


def test_malformed_catalog_and_quiz_are_one_line_errors(course: Path) -> None:
    _run("extract")
    _run("update")
    po = course / "locales" / "ur" / "LC_MESSAGES" / "content.po"
    po.write_text(po.read_text() + '\nmsgid "broken\n')
    code, output = _run("compile")
    assert code == 2 and output.strip().startswith(f"Error: {po}:")
    quiz = course / "quizzes" / "part2-rclpy.yaml"
    quiz.write_text(quiz.read_text().replace("type: single", "type: essay", 1))
    code, output = _run("extract")
    assert code == 2 and "part2-rclpy.yaml:8: questions[callback-groups-purpose].type" in output
    assert len(output.strip().splitlines()) == 1
