"""``autograder gradebook export --format moodle|canvas``: the gradebook (one row per student
and item) pivoted into the CSV an LMS gradebook imports: one row per student, a column per
item (exercise or quiz) holding its score in points, as a decimal.

Each layout is the one the LMS itself exports, since each imports what it exports:

- Moodle ("Grade import", https://docs.moodle.org/311/en/Grade_import): a column naming the
  user and a column per grade item; on import, map "ID number" to the user's ID number (or
  username) and each item column to its grade item.
- Canvas ("Import a CSV file to Carmen Grades", https://teaching.resources.osu.edu/toolsets/
  carmencanvas/guides/calculating-final-grades/import-csv-file-carmen-grades, after Canvas's
  own "How do I import grades in the Gradebook?"): the columns Student, ID, SIS User ID,
  SIS Login ID, Section, then one per assignment; a "Points Possible" row may follow the
  header. A column Canvas has no assignment for becomes a new assignment of those points.

A student is named by the folder (or file) name their submission was graded from, which
must be what the LMS knows them by: their SIS login in Canvas, their ID number in Moodle.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable
from pathlib import Path

from autograder.commands.gradebook import Row
from autograder.core.files import write_atomically

FORMATS = ("moodle", "canvas")
CANVAS_USER_COLUMNS = ["Student", "ID", "SIS User ID", "SIS Login ID", "Section"]
MOODLE_USER_COLUMN = "ID number"


def _pivot(rows: Iterable[Row]) -> tuple[list[str], dict[str, str], dict[str, dict[str, str]]]:
    """(items in order, each item's points possible, each student's score per item)."""
    items: dict[str, str] = {}
    students: dict[str, dict[str, str]] = {}
    for row in rows:
        items.setdefault(row["item"], row.get("max_score", ""))
        # A grader error is no score: left blank, so the LMS keeps what it had.
        score = "" if row.get("passed") == "grader error" else row.get("score", "")
        students.setdefault(row["student"], {})[row["item"]] = score
    order = sorted(items)
    return order, {i: items[i] for i in order}, {s: students[s] for s in sorted(students)}


def layout(rows: Iterable[Row], fmt: str) -> list[list[str]]:
    """The CSV's rows, header first, in the layout of ``fmt`` (``moodle`` or ``canvas``)."""
    items, possible, students = _pivot(rows)
    if fmt == "moodle":
        return [[MOODLE_USER_COLUMN, *items],
                *([student, *(scores.get(i, "") for i in items)]
                  for student, scores in students.items())]
    if fmt == "canvas":
        return [[*CANVAS_USER_COLUMNS, *items],
                ["    Points Possible", "", "", "", "", *(possible[i] for i in items)],
                *([student, "", "", student, "", *(scores.get(i, "") for i in items)]
                  for student, scores in students.items())]
    raise ValueError(f"unknown format {fmt!r}")


def export(path: Path, rows: Iterable[Row], fmt: str) -> int:
    """Write the ``fmt`` layout of ``rows`` to ``path``; return the number of students."""
    table = layout(rows, fmt)
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerows(table)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_atomically(path, buffer.getvalue())
    return len(table) - (2 if fmt == "canvas" else 1)
