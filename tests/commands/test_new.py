"""`autograder new exercise|quiz`: a scaffold in a copy of a course passes `validate`, the
content checks (READMEs, catalogs, the proof's data) and grades as a proof expects."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest
import yaml
from click.testing import CliRunner

from autograder.cli import main
from autograder.commands.validate import validate
from autograder.core.exercise import find_exercise
from autograder.i18n import translations
from autograder.i18n.glossary import check_language
from autograder.quiz.catalog import find_quiz
from autograder.quiz.scoring import score
from autograder.quiz.types import registry

REPO = Path(__file__).resolve().parents[2]
MINI = Path(__file__).parents[1] / "fixtures" / "mini_course"
sys.path.insert(0, str(Path(__file__).parents[1]))
from proving import load_variant  # noqa: E402


def _locales() -> Path:
    """The project's catalogs, wherever they live now (a course's or the package's)."""
    for folder in (REPO / "locales", REPO / "autograder" / "locales"):
        if (folder / "ur" / "LC_MESSAGES" / "content.po").exists():
            return folder
    raise AssertionError("no Urdu catalogs in the project")


@pytest.fixture
def course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The mini course with the project's catalogs and glossary, and a tests/ for proofs."""
    root = tmp_path / "course"
    shutil.copytree(MINI, root)
    shutil.copytree(_locales(), root / "locales")
    (root / "tests").mkdir()
    monkeypatch.setenv("AUTOGRADER_COURSE", str(root))
    monkeypatch.setenv("AUTOGRADER_LOCALES", str(root / "locales"))
    translations.cache_clear()
    yield root
    translations.cache_clear()


def _new(*args: str) -> str:
    result = CliRunner().invoke(main, ["new", *args])
    assert result.exit_code == 0, result.output
    return result.output


def _lines(course: Path) -> dict[Path, int]:
    return {p: len(p.read_text(encoding="utf-8").splitlines())
            for p in (course / "locales").rglob("*.po")}


def _mine(problems: list, before: dict[Path, int]) -> list[str]:
    """The problems at the scaffold's own files or at the catalog lines it added (the
    copied catalogs may lag the platform's strings: not the scaffold's to fix)."""
    return [str(p) for p in problems
            if "greeter" in str(p.path) or (p.line or 0) > before.get(p.path, 10**9)]


def _appended(course: Path, before: dict[Path, int]) -> list[str]:
    """Language problems (glossary, grammar, the Urdu title) of what the scaffold wrote."""
    return _mine(check_language(course / "locales", "ur", course), before)


def test_a_new_exercise_passes_validate_and_the_content_checks(course: Path) -> None:
    catalogs = _lines(course)
    output = _new("exercise", "greeter")
    folder = course / "assignments" / "greeter"
    for name in ("exercise.yaml", "README.md", "README.ur.md", "starter/greeter.py",
                 "solution/greeter.py", "tests/public/test_greeter_public.py",
                 "tests/hidden/test_greeter_hidden.py"):
        assert (folder / name).is_file(), name
    assert "Next:" in output and "README.ur.md" in output  # what to fill in next
    assert _mine(validate(course, run_gradings=False), catalogs) == []
    assert _appended(course, catalogs) == []  # glossary, grammar, the Urdu title
    exercise = find_exercise("greeter")
    variant = load_variant(course / "tests" / "submissions" / "greeter" / "wrong_greeting",
                           exercise)  # the proof's own reader: well formed, the patch fits
    assert variant.kind == "mutant" and variant.loses == {"test_greets"}
    assert set(exercise.core) <= variant.loses
    assert 'PROOF = Proof("greeter")' in (course / "tests" / "test_grading_greeter.py"
                                          ).read_text()


def test_the_scaffold_refuses_a_bad_id_or_an_existing_one(course: Path) -> None:
    for args in (["exercise", "Greeter"], ["exercise", "shout"], ["quiz", "two words"]):
        result = CliRunner().invoke(main, ["new", *args])
        assert result.exit_code == 2, result.output
        assert "Traceback" not in result.output


def test_a_new_quiz_has_every_type_lints_and_scores(course: Path) -> None:
    catalogs = _lines(course)
    _new("quiz", "greeter-quiz")
    quiz = find_quiz("greeter-quiz").quiz
    assert {q.type for q in quiz.questions} == set(registry())
    assert _mine(validate(course, run_gradings=False), catalogs) == []
    assert _appended(course, catalogs) == []
    key = {q.id: yaml.safe_load(yaml.safe_dump(q.answer)) for q in quiz.questions}
    for lang in ("en", "ur"):
        result = score(quiz, key, lang)
        assert result.score == result.max_score == len(quiz.questions)


@pytest.mark.slow
def test_the_scaffold_grades_as_its_proof_says(course: Path, tmp_path: Path) -> None:
    """validate grades the solution full and the starter below the pass mark; the known-bad
    variant loses exactly its core test."""
    from autograder.grading.run import grade

    catalogs = _lines(course)
    _new("exercise", "greeter")
    assert _mine(validate(course, jobs=1), catalogs) == []
    exercise = find_exercise("greeter")
    variant = load_variant(course / "tests" / "submissions" / "greeter" / "wrong_greeting",
                           exercise)
    result = grade(exercise, variant.submission(exercise, tmp_path))
    assert result.grader_error is None
    assert {t.name for t in result.tests if t.status != "passed"} == {"test_greets"}
    assert not result.passed
