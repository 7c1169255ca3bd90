"""Where the course tree is (content.course): ``$AUTOGRADER_COURSE``, else the nearest folder
up from the working one that holds ``assignments/``, else this checkout."""

from __future__ import annotations

from pathlib import Path

import pytest

from content.course import course_root

CHECKOUT = Path(__file__).resolve().parents[2]


def test_the_variable_wins(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("AUTOGRADER_COURSE", str(tmp_path / "." / "course"))
    monkeypatch.chdir(CHECKOUT)
    assert course_root() == (tmp_path / "course").resolve()


def test_the_nearest_folder_with_assignments_up_from_here(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("AUTOGRADER_COURSE", raising=False)
    (tmp_path / "assignments").mkdir()
    deep = tmp_path / "assignments" / "shout" / "solution"
    deep.mkdir(parents=True)
    monkeypatch.chdir(deep)
    assert course_root() == tmp_path.resolve()


def test_else_the_checkout_the_package_came_from(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("AUTOGRADER_COURSE", raising=False)
    monkeypatch.chdir(tmp_path)  # no assignments/ here nor above (/tmp)
    assert course_root() == CHECKOUT
