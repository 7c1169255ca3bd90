"""A submission is what Python runs (autograder/core/source.py): a file ``python FILE``
refuses, or one that is no node, is refused before any world starts, with exit 2 and one
sentence naming the file the student gave; a syntax error reads as Python prints it."""

from __future__ import annotations

import csv
import importlib.util
import json
import os
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest
from click.testing import CliRunner

from autograder.cli import main
from autograder.core.exercise import find_exercise
from autograder.core.source import SourceRefused, SourceSyntaxError, check_source
from autograder.grading.run import grade

EXERCISE = "parameter_validation"
NODE = "velocity_governor.py"
HEADER = "import rclpy\nfrom rclpy.node import Node\n\n"
URDU = range(0x0600, 0x0700)


def _latin1_comment(folder: Path) -> Path:
    path = folder / NODE
    path.write_bytes(HEADER.encode() + b"# caf\xe9\nclass G(Node):\n    pass\n")
    return path


def _syntax_error(folder: Path) -> Path:
    path = folder / NODE
    path.write_text(HEADER + "class G(Node):\n    def on_cmd(self, msg)\n        pass\n")
    return path


def _readme(folder: Path) -> Path:
    (folder / NODE).write_text(HEADER + "class G(Node):\n    pass\n")  # beside it: fine
    path = folder / "README.md"
    path.write_text("# My work\n")
    return path


def _text(folder: Path) -> Path:
    path = folder / "notes.txt"
    path.write_text("notes\n")
    return path


def _empty(folder: Path) -> Path:
    path = folder / NODE
    path.write_text("\n  \n")
    return path


def _no_node(folder: Path) -> Path:
    path = folder / NODE
    path.write_text("import math\n\nprint(math.pi)\n")
    return path


# Each bad input, and words its one sentence must hold (English) besides the file's name.
BAD: dict[str, tuple[Callable[[Path], Path], str]] = {
    "latin1_comment": (_latin1_comment, "line 4: the byte 0xe9 is not UTF-8"),
    "syntax_error": (_syntax_error, "does not compile"),
    "readme": (_readme, "is a README, not your node"),
    "text_file": (_text, "is not a Python file"),
    "empty": (_empty, "is empty"),
    "no_node": (_no_node, "creates no ROS node"),
}


def _given(tmp_path: Path, name: str) -> Path:
    folder = tmp_path / "mywork"
    folder.mkdir()
    return BAD[name][0](folder)


def _sentences(output: str) -> list[str]:
    """The lines of a refusal without Python's own (the indented source and caret, and
    the exception's last line)."""
    return [line for line in output.splitlines()
            if line.strip() and not line.startswith(" ") and "SyntaxError:" not in line]


@pytest.mark.parametrize("lang", ["en", "ur"])
@pytest.mark.parametrize("command", ["check", "grade"])
@pytest.mark.parametrize("name", list(BAD))
def test_a_bad_file_is_refused_in_one_sentence(tmp_path: Path, name: str, command: str,
                                                lang: str) -> None:
    given = _given(tmp_path, name)
    result = CliRunner().invoke(main, ["--lang", lang, command, EXERCISE, str(given)])
    assert result.exit_code == 2, result.output
    sentences = _sentences(result.output)
    assert len(sentences) == 1, result.output
    assert str(given) in sentences[0]
    assert (BAD[name][1] in sentences[0]) == (lang == "en"), result.output
    assert any(ord(c) in URDU for c in sentences[0]) == (lang == "ur"), result.output
    assert "Traceback" not in result.output and "Grading" not in result.output


@pytest.mark.parametrize("name", list(BAD))
def test_sim_run_refuses_the_same_files_before_its_world(tmp_path: Path, name: str) -> None:
    given = _given(tmp_path, name)
    result = CliRunner().invoke(main, ["sim", "run", "--node", str(given)])
    assert result.exit_code == 2, result.output
    assert len(_sentences(result.output)) == 1, result.output
    assert "World" not in result.output


@pytest.mark.parametrize("lang", ["en", "ur"])
@pytest.mark.parametrize("name", list(BAD))
def test_a_refusal_is_said_at_once_by_a_fresh_process(tmp_path: Path, name: str, lang: str,
                                                      record_property) -> None:
    """The whole command, interpreter start included, as a student runs it, the language
    from AUTOGRADER_LANG; the time is measured and recorded (the report's properties), not
    asserted."""
    given = _given(tmp_path, name)
    started = time.monotonic()
    proc = subprocess.run([sys.executable, "-m", "autograder", "check", EXERCISE, str(given)],
                          capture_output=True, text=True, timeout=60,
                          env={**os.environ, "AUTOGRADER_LANG": lang})
    seconds = time.monotonic() - started
    record_property("seconds", round(seconds, 3))
    print(f"{name} ({lang}): refused in {seconds:.2f} s")
    assert proc.returncode == 2, proc.stderr
    assert proc.stdout == ""
    [sentence] = _sentences(proc.stderr)
    assert str(given) in sentence
    assert any(ord(c) in URDU for c in sentence) == (lang == "ur"), sentence


def test_a_syntax_error_reads_as_python_prints_it(tmp_path: Path) -> None:
    given = _given(tmp_path, "syntax_error")
    python = subprocess.run([sys.executable, str(given)], capture_output=True, text=True,
                            timeout=60)
    assert python.returncode == 1
    result = CliRunner().invoke(main, ["check", EXERCISE, str(given)])
    # Python's own lines: the file, the line, the source with its caret, the error.
    assert python.stderr.strip() in result.output
    assert result.output.count("SyntaxError") == 1


def test_a_latin1_comment_is_refused_as_python_refuses_it(tmp_path: Path) -> None:
    given = _given(tmp_path, "latin1_comment")
    compile(given.read_bytes(), str(given), "exec")  # what let it through before
    python = subprocess.run([sys.executable, str(given)], capture_output=True, text=True,
                            timeout=60)
    assert python.returncode == 1 and "Non-UTF-8 code" in python.stderr
    with pytest.raises(SourceRefused, match="line 4: the byte 0xe9 is not UTF-8"):
        check_source({NODE: given.read_bytes()}, NODE, str(given))


NODE_CLASS = "class G(Node):\n    pass\n"


@pytest.mark.parametrize("files", [
    pytest.param({NODE: b"# -*- coding: latin-1 -*-\nfrom rclpy.node import Node\n# caf\xe9\n"
                        + NODE_CLASS.encode()}, id="latin1_cookie"),
    pytest.param({NODE: b"\xef\xbb\xbf" + (HEADER + NODE_CLASS).encode()}, id="utf8_bom"),
    pytest.param({NODE: b"import rclpy\nnode = rclpy.create_node('g')\n"}, id="create_node"),
    pytest.param({NODE: b"import rclpy.node\nclass G(rclpy.node.Node):\n    pass\n"},
                 id="qualified_base"),
    pytest.param({NODE: b"from rclpy.lifecycle import LifecycleNode\n"}, id="lifecycle"),
    pytest.param({NODE: b"from governor import main\nmain()\n",
                  "governor.py": (HEADER + NODE_CLASS).encode()}, id="node_in_a_module"),
])
def test_a_node_python_runs_is_taken(files: dict[str, bytes]) -> None:
    text = check_source(files, NODE, f"mywork/{NODE}")
    assert text == importlib.util.decode_source(files[NODE])  # the cookie's, without a BOM


def test_a_bad_cookie_is_python_s_syntax_error() -> None:
    with pytest.raises(SourceSyntaxError, match="encoding: bogus"):
        check_source({NODE: b"# coding: bogus\n" + HEADER.encode()}, NODE, NODE)


def test_future_flags_of_the_grader_do_not_leak_into_the_students_compile() -> None:
    """``from __future__ import annotations`` here must not let a student's file compile
    that ``python FILE`` refuses (a future import after code)."""
    source = (HEADER + "x = 1\nfrom __future__ import annotations\n" + NODE_CLASS).encode()
    with pytest.raises(SourceSyntaxError, match="from __future__ imports must occur"):
        check_source({NODE: source}, NODE, NODE)


def test_grading_a_syntax_error_scores_zero_with_one_message_and_no_world(
        tmp_path: Path) -> None:
    given = _given(tmp_path, "syntax_error")
    exercise = find_exercise(EXERCISE)
    result = grade(exercise, given.parent)
    assert result.grader_error is None
    assert (result.score, result.max_score) == (0, exercise.points)
    assert len(result.tests) == 1
    assert "    def on_cmd(self, msg)\n" in result.tests[0].message
    assert result.domain is None and result.processes == ()


def test_grade_batch_gives_a_refused_file_a_zero_with_its_message(tmp_path: Path) -> None:
    submissions = tmp_path / "class"
    submissions.mkdir()
    _given(tmp_path, "syntax_error").rename(submissions / "ali.py")
    (submissions / "sara").mkdir()
    (submissions / "sara" / "README.md").write_text("# my work\n")
    book, out = tmp_path / "book.csv", tmp_path / "out"
    result = CliRunner().invoke(main, ["grade-batch", EXERCISE, str(submissions), "--csv",
                                       str(book), "--out", str(out), "--allow-unofficial"])
    assert result.exit_code == 0, result.output
    with book.open(encoding="utf-8") as fh:
        rows = {row["student"]: row for row in csv.DictReader(fh)}
    assert {s: (r["score"], r["max_score"]) for s, r in rows.items()} == {
        "ali": ("0", "13"), "sara": ("0", "13")}
    ali = json.loads((out / "ali" / "results.json").read_text(encoding="utf-8"))
    [test] = ali["tests"]
    assert "does not compile" in test["message"] and "^" in test["message"]
    sara = json.loads((out / "sara" / "results.json").read_text(encoding="utf-8"))
    assert f"holds no {NODE}" in sara["tests"][0]["message"]
