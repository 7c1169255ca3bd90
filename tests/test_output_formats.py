"""The output formats come from one registry (autograder.render): the CLI's options, the
files `write_outputs` writes and grade-batch's files per student all follow it."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

from click.testing import CliRunner

from autograder.cli import main
from autograder.commands.grade import write_outputs
from autograder.core.results import RunResult, TestResult
from autograder.render import OutputFormat, formats


def result() -> RunResult:
    test = TestResult("test_a", "A works", Fraction(1), Fraction(1), "passed")
    return RunResult("exercise", "shout", "Shout", (test,), log="the program's output\n")


def test_every_module_with_a_format_is_registered():
    assert list(formats()) == ["results", "html", "gradescope", "junit"]
    assert all(isinstance(f, OutputFormat) for f in formats().values())


def test_check_and_grade_have_an_option_per_format():
    for command in ("check", "grade"):
        shown = CliRunner().invoke(main, [command, "--help"]).output
        for name in formats():
            assert f"--{name} FILE" in shown, (command, name)


def test_write_outputs_writes_every_format_and_the_log(tmp_path: Path):
    outputs = {name: tmp_path / f"out.{name}" for name in formats()}
    write_outputs(result(), outputs, tmp_path)
    for name, path in outputs.items():
        assert path.read_text() == formats()[name].render(result(), tmp_path)
    assert (tmp_path / "out.log").read_text() == "the program's output\n"
