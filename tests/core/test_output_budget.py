"""Bounded output: a test message carries a short tail of the program's output; the whole
kept output travels once, through files beside the raw report, to the results."""

from __future__ import annotations

import json
from fractions import Fraction
from pathlib import Path

import pytest

from autograder.commands.grade import batch_item, write_outputs
from autograder.core.output_budget import (
    CUT,
    LINE_CHARS,
    TAIL_BYTES,
    TAIL_LINES,
    clip_line,
    clip_middle,
    log_beside,
    log_folder,
    message_tail,
    size_note,
)
from autograder.core.report import output_log
from autograder.core.results import RunResult, TestResult
from autograder.core.signing import verify
from autograder.plugin.reporter import GradingReporter
from autograder.plugin.student import StudentNode
from autograder.render.html import to_html
from autograder.sandbox.process import BoundedOutput

KEY = b"k" * 32


def utf8(text: str) -> int:
    return len(text.encode())


def test_the_tail_keeps_the_last_lines():
    text = "\n".join(f"line {i}" for i in range(100)) + "\n\n"
    tail = message_tail(text, lines=TAIL_LINES)
    assert tail.splitlines() == [f"line {i}" for i in range(100 - TAIL_LINES, 100)]
    assert message_tail("one\ntwo", lines=1) == "two"
    assert message_tail("") == "" and message_tail("\n\n") == ""


def test_long_lines_are_cut_with_a_visible_mark():
    tail = message_tail("start\n" + "x" * 10_000 + "\nTraceback: the end")
    lines = tail.splitlines()
    assert lines == ["start", "x" * (LINE_CHARS - len(CUT)) + CUT, "Traceback: the end"]
    assert clip_line("short") == "short"
    assert len(clip_line("y" * 301)) == LINE_CHARS and clip_line("y" * 301).endswith(CUT)


def test_the_tail_fits_in_its_bytes_whatever_the_lines():
    wide = "\n".join("é" * 1000 for _ in range(50))  # 2 bytes a character
    tail = message_tail(wide)
    assert utf8(tail) <= TAIL_BYTES
    assert all(len(line) <= LINE_CHARS for line in tail.splitlines())
    one = message_tail("z" * 100_000, max_bytes=100, line_chars=10_000)
    assert utf8(one) <= 100 and one.endswith(CUT)  # a last line too long alone: its start
    flood = "x" * 262_144 + "\n[... 99 bytes of output dropped ...]\n" + "y" * 262_144
    assert utf8(message_tail(flood)) <= TAIL_BYTES


def test_the_note_says_when_output_was_cut():
    assert size_note(100, 1024) == ""
    note = size_note(5000, 1024)
    assert "5000 bytes of output; only the first and last 512 bytes were kept" in note


def test_clip_middle_keeps_both_ends():
    text = "BEGIN " + "m" * 50_000 + " END"
    clipped = clip_middle(text, 1000)
    assert clipped.startswith("BEGIN") and clipped.endswith("END") and CUT in clipped
    assert utf8(clipped) <= 1000 + 8
    assert clip_middle("small", 1000) == "small"


def test_log_names():
    assert log_beside(Path("out/results.json")) == Path("out/results.log")
    assert log_beside(Path("out/results.log")) == Path("out/results.log.log")
    assert log_folder(Path("/tmp/x/report.json")) == Path("/tmp/x/report.logs")


class FakeProcess:
    def __init__(self, output: BoundedOutput,
                 workdir: Path = Path("/tmp/autograder-student-x1")) -> None:
        self.output = output
        self.workdir = workdir

    def output_text(self) -> str:
        return self.output.text()


def flooded(budget: int = 1024) -> BoundedOutput:
    output = BoundedOutput(budget)
    output.feed(b"HEAD\n" + b"".join(b"line %d\n" % i for i in range(30)) + b"x" * 100_000
                + b"\nTraceback (most recent call last):\n"
                b"RuntimeError: the end\n")
    return output


def test_a_nodes_tail_is_short_and_says_it_was_cut():
    node = StudentNode(FakeProcess(flooded()), "shouter", probe=None)
    tail = node.output_tail()
    assert tail.splitlines()[-2] == "RuntimeError: the end"
    assert "only the first and last 512 bytes were kept" in tail.splitlines()[-1]
    assert "HEAD" not in tail and utf8(tail) <= TAIL_BYTES + 200


def test_a_tail_that_shows_rclpys_shutdown_race_explains_it():
    """The race every exercise README explains is named where a student reads it; any
    other traceback gets no such note."""
    race, other = BoundedOutput(4096), BoundedOutput(4096)
    race.feed(b"Traceback (most recent call last):\n  File \"x.py\", line 9, in main\n"
              b"RuntimeError: Unable to convert call argument '0' to Python object\n")
    other.feed(b"Traceback (most recent call last):\nRuntimeError: the end\n")
    tail = StudentNode(FakeProcess(race), "ai_agent", probe=None).output_tail()
    assert tail.splitlines()[-2].endswith("to Python object")
    assert "is rclpy's shutdown race" in tail.splitlines()[-1]
    assert "Shutting down cleanly, every time" in tail
    assert "shutdown race" not in StudentNode(FakeProcess(other), "x", probe=None).output_tail()


@pytest.mark.parametrize(("submitted", "shown"), [
    ("mywork/obstacle_avoider.py", 'File "mywork/obstacle_avoider.py", line 55, in on_scan'),
    ("obstacle_avoider.py", 'File "obstacle_avoider.py", line 55, in on_scan'),
    (None, 'File "obstacle_avoider.py", line 55, in on_scan')], ids=["folder", "bare", "none"])
def test_a_traceback_names_the_students_file_not_the_throwaway_copy(submitted, shown):
    from autograder.plugin.student import shown_folder

    output = BoundedOutput(4096)
    output.feed(b'Traceback (most recent call last):\n'
                b'  File "/tmp/autograder-student-x1/obstacle_avoider.py", line 55, in on_scan\n'
                b'  File "/tmp/autograder-student-x1/helpers.py", line 3, in ahead\n'
                b'ValueError: min() arg is an empty sequence\n')
    node = StudentNode(FakeProcess(output), "obstacle_avoider", probe=None,
                       shown_folder=shown_folder(submitted))
    assert shown in node.output() and shown in node.output_tail()
    assert "/tmp/autograder-student-x1" not in node.output()
    assert 'helpers.py", line 3' in node.output()  # a sibling module: the same folder


def test_the_whole_log_goes_beside_the_report_once(tmp_path):
    report = tmp_path / "report.json"
    reporter = GradingReporter(str(report), key=KEY)
    text = flooded(4096).text()
    reporter.keep_log("tests/test_a.py", text)
    reporter.keep_log("tests/test_b.py::test_b", "second program\n")
    reporter.keep_log("tests/test_c.py", "")  # no output: no file
    written = report.read_text()
    assert len(written) < 10_000  # the report names the logs, it does not hold them
    raw = verify(written, KEY)
    assert [e["test"] for e in raw["data"]["log_files"]] == ["tests/test_a.py",
                                                              "tests/test_b.py::test_b"]
    assert raw["data"]["logs"]["tests/test_a.py"].endswith("RuntimeError: the end")
    log = output_log(raw["data"], report)
    assert log.startswith("==> tests/test_a.py <==\nHEAD\n")
    assert text in log and "second program" in log


def test_a_log_changed_after_the_run_is_left_out(tmp_path):
    report = tmp_path / "report.json"
    reporter = GradingReporter(str(report), key=KEY)
    reporter.keep_log("tests/test_a.py", "the real output\n")
    (log_folder(report) / "001.log").write_text("the forged output\n")
    log = output_log(verify(report.read_text(), KEY)["data"], report)
    assert "forged" not in log and "real" not in log
    assert "changed after your program ran" in log


def run_result(log: str) -> RunResult:
    test = TestResult("test_starts", "The node starts", Fraction(0), Fraction(1), "failed",
                      message="Last lines of its output:\nRuntimeError: the end")
    return RunResult("exercise", "shout", "Shout", (test,), log_tail="RuntimeError: the end",
                     log=log)


def test_the_log_is_in_the_html_once_and_in_a_file_beside_the_results(tmp_path):
    log = "==> tests/test_a.py <==\nHEAD <b>\n" + "x" * 1000 + "\nRuntimeError: the end"
    result = run_result(log)
    html = to_html(result)
    assert html.count("HEAD &lt;b&gt;") == 1 and "<details" in html
    assert "The end of your node" not in html  # the tail is in the log already
    write_outputs(result, {"results": tmp_path / "results.json", "html": None}, tmp_path)
    assert (tmp_path / "results.log").read_text() == log
    assert log not in (tmp_path / "results.json").read_text()
    assert "HEAD" not in json.dumps(result.to_dict())


def test_without_the_whole_log_the_html_shows_the_tail():
    html = to_html(run_result(""))
    assert "The end of your node" in html and "<details" not in html


def test_a_batch_writes_each_students_log(tmp_path, monkeypatch):
    monkeypatch.setenv("AUTOGRADER_COURSE", str(Path(__file__).parents[1] / "fixtures" /
                                                 "mini_course"))
    _grade, _suffix, extra = batch_item("shout")
    extra(run_result("the student's output\n"), tmp_path)
    assert (tmp_path / "output.log").read_text() == "the student's output\n"
    assert "the student&#39;s output" in (tmp_path / "report.html").read_text()
