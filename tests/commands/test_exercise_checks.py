"""`validate` requires what the project's content tests require of an exercise, naming
the file and the line: both READMEs, the hand-run section, a grading table that is the
tests' own, test modules pytest can collect, the proof (autograder/commands/exercise_checks)."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest

from autograder.commands.validate import validate
from autograder.i18n import translations

MINI = Path(__file__).parents[1] / "fixtures" / "mini_course"


@pytest.fixture
def course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    root = tmp_path / "course"
    shutil.copytree(MINI, root)
    monkeypatch.setenv("AUTOGRADER_COURSE", str(root))
    translations.cache_clear()  # the grading table reads labels in the course's catalogs
    yield root
    translations.cache_clear()


def problems(course: Path) -> list[str]:
    return [str(p) for p in validate(course, run_gradings=False)]


def readme(course: Path, name: str = "README.md") -> Path:
    return course / "assignments" / "shout" / name


def line_of(path: Path, text: str) -> int:
    return next(n for n, line in enumerate(path.read_text().splitlines(), 1) if text in line)


def test_the_fixture_course_is_clean(course: Path) -> None:
    assert problems(course) == []


def test_a_missing_urdu_readme_is_named(course: Path) -> None:
    readme(course, "README.ur.md").unlink()
    found = problems(course)
    assert len(found) == 1 and "README.ur.md is missing" in found[0], found


def test_the_hand_run_section_and_command_are_required(course: Path) -> None:
    path = readme(course)
    text = path.read_text()
    path.write_text(text.replace("### Trying your node by hand\n", "### By hand\n"))
    assert any(p.startswith(f"{path}:1: no section '### Trying your node by hand'")
               for p in problems(course))
    path.write_text(text.replace("--node mydir/shouter.py", "--node shouter.py"))
    line = line_of(path, "--node shouter.py")
    assert any(p.startswith(f"{path}:{line}: the hand run names empty_room and shouter.py")
               for p in problems(course)), problems(course)
    path.write_text(text.replace("autograder sim run --world empty_room --node "
                                 "mydir/shouter.py\n", ""))
    assert any("no hand run: show `autograder sim run --world empty_room --node "
               "mydir/shouter.py`" in p for p in problems(course))


def test_each_row_of_the_grading_table_is_a_test_as_graded(course: Path) -> None:
    path = readme(course, "README.ur.md")
    text = path.read_text()
    path.write_text(text.replace("| What it hears comes out upper-cased | 1 | public | "
                                 "**بنیادی** |", "| What it hears comes out upper-cased | 2 "
                                 "| public |  |"))
    line = line_of(path, "upper-cased")
    assert [p for p in problems(course) if "upper" in p or "test_upper_case" in p] == [
        f"{path}:{line}: the row of test_upper_case says 2 | public | ; its test says "
        "1 | public | **بنیادی**"]
    path.write_text(text.replace("| Each message is answered exactly once | 1 | hidden |  |\n",
                                 "| Each message is answered twice | 1 | hidden |  |\n"))
    found = problems(course)
    assert any("has no row for test_once_per_message" in p for p in found), found
    assert any("row 'Each message is answered twice' is no test's label" in p for p in found)


def test_a_tables_simulation_seconds_are_a_number_or_wall_time(course: Path) -> None:
    """A fifth column gives each test's simulation seconds (the proofs hold them to the
    reference's gradings), or "wall time" for a test timed on the wall clock."""
    path = readme(course)
    text = path.read_text()
    for row, cell in (("| test | points | visibility | core |", " simulation s |"),
                      ("|---|---|---|---|", "---|"),
                      ("| The node starts and publishes on shout | 1 | public |  |", " 2.5 |"),
                      ("| What it hears comes out upper-cased | 1 | public | **core** |",
                       " wall time |"),
                      ("| Each message is answered exactly once | 1 | hidden |  |", " soon |")):
        assert row in text
        text = text.replace(row, row + cell)
    path.write_text(text)
    line = line_of(path, "answered exactly once")
    assert [p for p in problems(course) if "simulation seconds" in p] == [
        f"{path}:{line}: the row of test_once_per_message gives 'soon' as its simulation "
        "seconds: a number, such as 2.5, or 'wall time' for a test timed on the wall clock"]


def test_two_test_modules_of_one_name_are_named(course: Path) -> None:
    tests = course / "assignments" / "shout" / "tests"
    shutil.copy(tests / "hidden" / "test_once.py", tests / "public" / "test_once.py")
    found = problems(course)
    assert any("test_once.py is also" in p for p in found), found


def test_a_course_with_tests_needs_each_exercise_s_proof(course: Path) -> None:
    (course / "tests").mkdir()
    found = problems(course)
    assert any(p.startswith(f"{course / 'tests' / 'test_grading_shout.py'}:1: no proof")
               for p in found), found
    assert any("no known-bad submission: a folder here" in p for p in found)
    variant = course / "tests" / "submissions" / "shout" / "relays"
    variant.mkdir(parents=True)
    (variant / "expect.yaml").write_text("kind: mutant\nwhy: relays\n"
                                         "loses: [test_once_per_message]\n")
    (course / "tests" / "test_grading_shout.py").write_text('PROOF = Proof("shout")\n')
    assert problems(course) == [f"{variant.parent}:1: no known-bad submission loses the "
                                "core test test_upper_case"]


def test_an_exercise_without_a_public_test_is_named(course: Path) -> None:
    public = course / "assignments" / "shout" / "tests" / "public"
    (public / "test_shout.py").rename(public / "shout_checks.py")
    found = problems(course)
    assert any(p.startswith(f"{public}:1: no public test") for p in found), found


def test_an_untranslated_label_is_named_at_its_test(course: Path) -> None:
    catalog = course / "locales" / "ur" / "LC_MESSAGES" / "messages.po"
    catalog.parent.mkdir(parents=True)
    catalog.write_text('msgid ""\nmsgstr ""\n"Content-Type: text/plain; charset=utf-8\\n"\n\n'
                       'msgid "What it hears comes out upper-cased"\nmsgstr "بڑے حروف میں"\n\n'
                       'msgid "Each message is answered exactly once"\nmsgstr "ایک بار"\n',
                       encoding="utf-8")
    public = course / "assignments" / "shout" / "tests" / "public" / "test_shout.py"
    line = line_of(public, "def test_starts")
    assert [p for p in problems(course) if "has no translation" in p] == [
        f"{public}:{line}: ur: the label of test_starts has no translation in {catalog}"]
