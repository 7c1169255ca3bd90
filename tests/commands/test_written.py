"""Where a command wrote its files, said on stderr only (stdout may be a pipe), one line per
file: the HTML report to open, the programs' log, any other ``--NAME``; in the student's
language, laid out for a right-to-left terminal."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from autograder.commands.written import say_written
from autograder.i18n import set_language

WRITTEN = [("html", Path("out/r.html")), ("log", Path("out/run.log")),
           ("junit", Path("out/j.xml"))]


@pytest.fixture(autouse=True)
def english_after() -> Iterator[None]:
    set_language("en")
    yield
    set_language("en")


def test_one_line_per_file_on_stderr_only(capsys):
    say_written(WRITTEN)
    out, err = capsys.readouterr()
    assert out == ""
    assert err.splitlines() == [
        "Wrote out/r.html (--html): open it in a browser.",
        "Wrote out/run.log: the programs' whole output.",
        "Wrote out/j.xml (--junit)."]
    say_written([])
    assert capsys.readouterr() == ("", "")


def test_in_urdu_laid_out_for_a_right_to_left_terminal(capsys):
    set_language("ur")
    say_written(WRITTEN)
    html, log, junit = capsys.readouterr().err.splitlines()
    assert "براؤزر میں کھولیں" in html and "out/r.html" in html
    assert "پروگراموں کا پورا output" in log
    assert "(--junit)" in junit and "لکھ دی گئی" in junit
    # A line that starts with a path (left to right) is marked right-to-left first.
    assert all(line.startswith("\u200f") for line in (html, log, junit))
