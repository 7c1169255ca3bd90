"""The raw grading report (autograder.core.report): what the pytest child writes, signed,
and what the grader reads back; the programs' output beside it, read only as vouched for."""

from __future__ import annotations

import json
import os
from pathlib import Path

from autograder.core.report import RawReport, RawTest, keep_log, output_log, read, write
from autograder.core.signing import sign

KEY = b"k" * 32


def raw_test(name: str = "test_starts", **fields: object) -> RawTest:
    return RawTest(f"tests/public/test_a.py::{name}", name, "Starts", 2, "visible",
                   "message", **fields)  # type: ignore[arg-type]


def test_what_the_child_wrote_reads_back(tmp_path: Path) -> None:
    path = tmp_path / "report.json"
    tests = [raw_test(done=True, status="failed", message="no", fraction=0.5),
             raw_test("test_stops")]
    write(path, tests, {"processes": [{"pid": 7}], "pacing": {"m": {"idle": 1}}}, KEY)
    report = read(path, KEY)
    assert report.tests == tests and not report.forged
    assert report.processes == [{"pid": 7}] and report.data["pacing"] == {"m": {"idle": 1}}
    assert not path.with_suffix(".tmp").exists()  # replaced in one step


def test_no_report_yet_is_an_empty_one_and_another_writer_is_forged(tmp_path: Path) -> None:
    path = tmp_path / "report.json"
    assert read(path, KEY) == RawReport()
    path.write_text(sign(json.dumps({"tests": [], "data": {"score": 100}}), b"guessed"))
    assert read(path, KEY) == RawReport(forged=True)
    path.write_text("{ not json")
    assert read(path, KEY).forged


def test_a_field_of_a_newer_child_is_left_out(tmp_path: Path) -> None:
    path = tmp_path / "report.json"
    entry = {**json.loads(json.dumps(raw_test().__dict__)), "from_the_future": 1}
    path.write_text(sign(json.dumps({"tests": [entry], "data": {}}), KEY))
    assert read(path, KEY).tests == [raw_test()]


def logged(tmp_path: Path, *outputs: str) -> tuple[Path, dict]:
    path = tmp_path / "report.json"
    data: dict = {"log_files": []}
    for index, text in enumerate(outputs):
        keep_log(path, data, f"tests/public/test_{index}.py", text)
    write(path, [], data, KEY)
    return path, data


def test_each_programs_output_is_read_as_vouched_for(tmp_path: Path) -> None:
    path, data = logged(tmp_path, "first\n", "second ✓\n")
    assert [e["file"] for e in data["log_files"]] == ["001.log", "002.log"]
    report = read(path, KEY, with_logs=True)
    assert report.output_log == ("==> tests/public/test_0.py <==\nfirst\n\n\n"
                                 "==> tests/public/test_1.py <==\nsecond ✓\n")


def test_a_log_changed_or_swapped_afterwards_is_left_out(tmp_path: Path) -> None:
    path, data = logged(tmp_path, "real\n", "also real\n")
    logs = tmp_path / "report.logs"
    (logs / "001.log").write_text("fake\n")  # same size, other bytes
    (logs / "002.log").write_text("x" * 100_000)  # another size: not even read
    text = output_log(data, path)
    assert "fake" not in text and "x" * 10 not in text and "real" not in text
    assert text.count("changed after your program ran") == 2


def test_a_log_named_outside_its_folder_is_never_read(tmp_path: Path) -> None:
    path, data = logged(tmp_path, "kept\n")
    (tmp_path / "secret.log").write_text("kept\n")
    data["log_files"][0]["file"] = "../secret.log"  # only its name counts: 001's folder
    assert "kept" not in output_log(data, path)


def test_a_log_swapped_for_a_link_or_a_fifo_is_left_out_without_waiting(
        tmp_path: Path) -> None:
    """A link to a file with the very bytes vouched for is not followed, and a FIFO in a
    log's place is not opened for a read that would wait for a writer forever."""
    path, data = logged(tmp_path, "same\n", "piped\n")
    logs = tmp_path / "report.logs"
    elsewhere = tmp_path / "elsewhere.log"
    elsewhere.write_text("same\n")
    (logs / "001.log").unlink()
    (logs / "001.log").symlink_to(elsewhere)
    (logs / "002.log").unlink()
    os.mkfifo(logs / "002.log")
    text = output_log(data, path)
    assert "same" not in text and "piped" not in text
    assert text.count("changed after your program ran") == 2
