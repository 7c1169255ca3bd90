"""``autograder quiz export`` (autograder.quiz.export and the command): both formats
written, and bad input refused with exit code 2. Each format's content is checked in
tests/quiz/export/."""

from __future__ import annotations

import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner
from quiz_exports import FILES

from autograder.cli.quiz import quiz_cli
from autograder.quiz.model import Question
from autograder.quiz.types import registry
from autograder.quiz.types.single import SingleChoice


class NoExport(SingleChoice):
    """A type that has no LMS form: the export must name the question, not crash."""

    name = "no_export"

    def moodle_question(self, q: Question, moodle: Any) -> Any:
        return super(SingleChoice, self).moodle_question(q, moodle)

    def qti_item(self, q: Question, qti: Any) -> Any:
        return super(SingleChoice, self).qti_item(q, qti)


def test_export_command_writes_both_formats(tmp_path: Path) -> None:
    runner = CliRunner()
    out = tmp_path / "part2.xml"
    result = runner.invoke(quiz_cli, ["export", "rclpy-part2", "--format", "moodle-xml",
                                      "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert result.output.strip() == str(out)
    root = ET.fromstring(out.read_text(encoding="utf-8"))
    assert len(root.findall("question")) == 2 + 5
    out = tmp_path / "all.zip"
    result = runner.invoke(quiz_cli, ["export", "--format", "qti", "--lang", "ur",
                                      "--out", str(out)])
    assert result.exit_code == 0, result.output
    with zipfile.ZipFile(out) as zf:
        assert {n.split("/")[0] for n in zf.namelist()} == {
            "imsmanifest.xml", *(qf.quiz.id for qf in FILES)}


def test_export_command_bad_input_exits_2(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    runner = CliRunner()
    result = runner.invoke(quiz_cli, ["export", "nope", "--format", "qti"])
    assert result.exit_code == 2 and "No quiz named nope" in result.output
    result = runner.invoke(quiz_cli, ["export", "rclpy-part2", "--format", "pdf"])
    assert result.exit_code == 2
    blocker = tmp_path / "file"
    blocker.write_text("")
    result = runner.invoke(quiz_cli, ["export", "rclpy-part2", "--format", "moodle-xml",
                                      "--out", str(blocker / "x.xml")])
    assert result.exit_code == 2 and "cannot write" in result.output

    monkeypatch.setitem(registry(), "no_export", NoExport())
    path = tmp_path / "toy.yaml"
    path.write_text("id: toy\ntitle: Toy\nlanguages: [en]\n"  # English: no catalog needed
                    "questions:\n  - id: pick\n    type: no_export\n"
                    "    text: Pick.\n    options: [{id: a, text: A}, {id: b, text: B}]\n"
                    "    answer: a\n")
    for fmt in ("moodle-xml", "qti"):
        result = runner.invoke(quiz_cli, ["export", str(path), "--format", fmt,
                                          "--out", str(tmp_path / "x")])
        assert result.exit_code == 2, result.output
        assert f"toy.yaml:5: questions[pick]: a no_export question cannot be exported to {fmt}" \
            in result.output
