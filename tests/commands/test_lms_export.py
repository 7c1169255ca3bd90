"""Batch output in decimals, and `gradebook export --format moodle|canvas`: one row per
student, a column per item, in the layouts the LMSs document for import
(autograder/commands/lms_export.py cites them)."""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from autograder.cli import main

HEADER = "student,item,score,max_score,passed\n"
BOOK = HEADER + ("amna,timer_sync,6.6667,14,no\n"
                 "amna,callback-groups,4,5,yes\n"
                 "bilal,timer_sync,14,14,yes\n"
                 "chen,timer_sync,0,14,grader error\n")
# Canvas: "Student, ID, SIS User ID, SIS Login ID, Section", then one column per assignment.
CANVAS_COLUMNS = ["Student", "ID", "SIS User ID", "SIS Login ID", "Section"]


def _export(tmp_path: Path, fmt: str) -> list[list[str]]:
    book = tmp_path / "grades.csv"
    book.write_text(BOOK)
    out = tmp_path / f"{fmt}.csv"
    result = CliRunner().invoke(main, ["gradebook", "export", "--format", fmt, str(out),
                                       str(book)])
    assert result.exit_code == 0, result.output
    assert result.output == f"3 students in {out}\n"
    with out.open(newline="") as fh:
        return list(csv.reader(fh))


def test_moodle_layout_is_a_user_column_and_a_column_per_item(tmp_path: Path) -> None:
    rows = _export(tmp_path, "moodle")
    assert rows[0] == ["ID number", "callback-groups", "timer_sync"]
    assert rows[1:] == [["amna", "4", "6.6667"], ["bilal", "", "14"], ["chen", "", ""]]


def test_canvas_layout_has_its_user_columns_and_points_possible(tmp_path: Path) -> None:
    rows = _export(tmp_path, "canvas")
    assert rows[0] == [*CANVAS_COLUMNS, "callback-groups", "timer_sync"]
    assert rows[1][0].strip() == "Points Possible" and rows[1][5:] == ["5", "14"]
    by_login = {r[3]: r[5:] for r in rows[2:]}
    assert by_login == {"amna": ["4", "6.6667"], "bilal": ["", "14"], "chen": ["", ""]}
    assert all(r[0] == r[3] for r in rows[2:])  # Student and SIS Login ID: the same name


def test_a_file_that_is_no_gradebook_is_refused(tmp_path: Path) -> None:
    other = tmp_path / "other.csv"
    other.write_text("name,grade\namna,3\n")
    result = CliRunner().invoke(main, ["gradebook", "export", "--format", "canvas",
                                       str(tmp_path / "out.csv"), str(other)])
    assert result.exit_code == 2 and "not a gradebook" in result.output


QUIZ = """\
id: thirds
title: Thirds
languages: [en]
questions:
  - id: all
    type: multiple
    partial_credit: true
    text: Pick all three
    options: [{id: a, text: A}, {id: b, text: B}, {id: c, text: C}]
    answer: [a, b, c]
"""


@pytest.fixture
def course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    (tmp_path / "assignments").mkdir()
    (tmp_path / "quizzes").mkdir()
    (tmp_path / "quizzes" / "thirds.yaml").write_text(QUIZ)
    monkeypatch.setenv("AUTOGRADER_COURSE", str(tmp_path))
    return tmp_path


def test_batch_progress_prints_decimals_not_fractions(course: Path, tmp_path: Path) -> None:
    answers = tmp_path / "answers"
    answers.mkdir()
    (answers / "bob.json").write_text(json.dumps({"quiz": "thirds",
                                                  "answers": {"all": ["a"]}}))
    result = CliRunner().invoke(main, ["grade-batch", "thirds", str(answers),
                                       "--csv", str(tmp_path / "grades.csv"),
                                       "--out", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    line = next(x for x in result.output.splitlines() if x.startswith("bob: "))
    assert re.fullmatch(r"bob: 0\.\d+/1", line), line
