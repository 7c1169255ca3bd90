"""The gradebook: one CSV row per (student, item), items being exercises and quizzes.

Columns: ``student, item, score, max_score, passed`` and then one column per test,
``<item>:<test>``, holding that test's points.  Gradebooks from several batches or shards
merge by (student, item); a later file wins a duplicate row.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable
from pathlib import Path

from autograder.core.errors import ContentError
from autograder.core.files import write_atomically
from autograder.core.results import RunResult, number
from autograder.i18n import _

BASE_COLUMNS = ["student", "item", "score", "max_score", "passed"]

Row = dict[str, str]


def row_for(student: str, result: RunResult) -> Row:
    row = {"student": student, "item": result.id, "score": str(number(result.score)),
           "max_score": str(number(result.max_score)),
           "passed": "yes" if result.passed else "no"}
    for test in result.tests:
        row[f"{result.id}:{test.name}"] = str(number(test.score))
    if result.grader_error:
        row["passed"] = "grader error"
    return row


def read(path: Path) -> list[Row]:
    """Rows of a gradebook CSV; a file without our columns is a ContentError."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ContentError(path, _("file not found")) from None
    reader = csv.DictReader(io.StringIO(text))
    missing = [c for c in BASE_COLUMNS if c not in (reader.fieldnames or [])]
    if missing:
        raise ContentError(path, _("not a gradebook: missing columns {columns}").format(
            columns=", ".join(missing)), 1)
    return [{k: v for k, v in row.items() if v not in (None, "")} for row in reader]


def merge(*books: Iterable[Row]) -> list[Row]:
    """Union of gradebooks keyed by (student, item), sorted; later books win."""
    merged: dict[tuple[str, str], Row] = {}
    for book in books:
        for row in book:
            merged[(row["student"], row["item"])] = row
    return [merged[key] for key in sorted(merged)]


def write(path: Path, rows: list[Row]) -> None:
    """Write atomically, so a crash never leaves half a gradebook."""
    extra = sorted({k for row in rows for k in row} - set(BASE_COLUMNS))
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=BASE_COLUMNS + extra, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_atomically(path, buffer.getvalue())
