"""Exercise files (autograder.core.exercise): ``exercise.yaml`` parsed into an Exercise, each
mistake a ContentError naming the file and line, and exercises found by id or by folder."""

from __future__ import annotations

import textwrap
from fractions import Fraction
from pathlib import Path

import pytest

from autograder.core.errors import ContentError
from autograder.core.exercise import (
    Exercise,
    Limits,
    find_exercise,
    list_exercises,
    load_each_exercise,
    load_exercise,
)
from autograder.core.exercise import test_names as names_of_tests  # not a test itself

MINIMAL = """\
id: shout
title: Shout
file: shout.py
node: shouter
"""


@pytest.fixture
def course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty course (``AUTOGRADER_COURSE``) whose exercises the test writes."""
    (tmp_path / "assignments").mkdir()
    monkeypatch.setenv("AUTOGRADER_COURSE", str(tmp_path))
    return tmp_path


def write(course: Path, folder: str, text: str) -> Path:
    path = course / "assignments" / folder
    path.mkdir(parents=True, exist_ok=True)
    (path / "exercise.yaml").write_text(textwrap.dedent(text))
    return path


def test_a_minimal_file_takes_every_default(course: Path) -> None:
    exercise = load_exercise(write(course, "shout", MINIMAL))
    assert (exercise.id, exercise.title, exercise.file, exercise.node) == (
        "shout", "Shout", "shout.py", "shouter")
    assert exercise.limits == Limits() and exercise.world == "empty_room"
    assert exercise.pass_fraction == Fraction(7, 10)  # exact, from the decimal text
    assert exercise.folder == (course / "assignments" / "shout").resolve()
    assert exercise.starter == exercise.folder / "starter" / "shout.py"
    assert exercise.hidden_tests == exercise.folder / "tests" / "hidden"


def test_limits_and_the_rest_are_read_from_the_file(course: Path) -> None:
    exercise = load_exercise(write(course, "shout", MINIMAL + """\
points: 12
pass_mark: 0.75
core: [test_starts]
real_time_factor: 2.5
limits: {memory_mb: 1024, output_kb: 64}
"""))
    assert exercise.points == 12 and exercise.core == ("test_starts",)
    assert exercise.pass_fraction == Fraction(3, 4) and exercise.real_time_factor == 2.5
    assert exercise.limits == Limits(memory_mb=1024, output_kb=64)


# Every mistake is reported at its field's line, the Exercise's own checks (its
# __post_init__) too.
@pytest.mark.parametrize(("extra", "where", "message"), [
    ("pass_mark: 1.5\n", ":6: pass_mark", "pass_mark must be above 0 and at most 1"),
    ("core: [a, a]\n", ":6: core", "core names a test more than once"),
    ("folder: /etc\n", ":6: folder", "set by the loader, not in the file"),
    ("limits: {memory_mb: lots}\n", ":6: limits.memory_mb", ""),
    ("hidden_visibility: secret\n", ":6: hidden_visibility", "must be one of"),
    ("colour: red\n", ":6: colour", ""),
], ids=["pass-mark", "core-twice", "folder", "limit-type", "visibility", "unknown-field"])
def test_a_mistake_names_the_file_and_line(course: Path, extra: str, where: str,
                                          message: str) -> None:
    folder = write(course, "shout", MINIMAL + "\n" + extra)
    with pytest.raises(ContentError) as error:
        load_exercise(folder)
    text = str(error.value)
    assert text.startswith(str(folder / "exercise.yaml")) and where in text, text
    assert message in text


def test_the_id_must_be_the_folders_name(course: Path) -> None:
    folder = write(course, "not_shout", MINIMAL)
    with pytest.raises(ContentError, match=r"exercise.yaml:1: id: must equal the folder name "
                                           r"'not_shout'"):
        load_exercise(folder)


def test_exercises_are_found_by_id_or_folder_and_a_typo_is_named(course: Path) -> None:
    write(course, "shout", MINIMAL)
    write(course, "whisper", MINIMAL.replace("shout", "whisper"))
    assert [e.id for e in list_exercises()] == ["shout", "whisper"]
    assert find_exercise("whisper").id == "whisper"
    assert find_exercise(str(course / "assignments" / "shout")).id == "shout"
    with pytest.raises(ContentError, match="No exercise named shoot. Did you mean shout?"):
        find_exercise("shoot")


def test_one_bad_file_is_one_problem(course: Path) -> None:
    write(course, "shout", MINIMAL)
    write(course, "broken", "id: broken\ntitle: [unclosed\n")
    found, errors = load_each_exercise()
    assert [e.id for e in found] == ["shout"]
    assert len(errors) == 1 and "broken" in str(errors[0])


def test_test_names_are_read_without_importing(tmp_path: Path) -> None:
    tests = tmp_path / "tests" / "public"
    tests.mkdir(parents=True)
    (tests / "test_a.py").write_text("import nothing_here\n\ndef test_one():\n    pass\n\n"
                                     "async def test_two():\n    pass\n\ndef helper():\n"
                                     "    pass\n")
    (tests / "test_broken.py").write_text("def test_(:\n")
    exercise = Exercise("x", "X", "x.py", "x", folder=tmp_path)
    assert names_of_tests(exercise) == {"test_one", "test_two"}
