"""The student's submission (autograder.core.submission), read as untrusted input by a
process that may run as root (issue 28): the node file found in what was submitted, and
links, devices, FIFOs and oversized files refused by name, never followed or read."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from autograder.cli import main
from autograder.core.submission import (
    MAX_FILE_BYTES,
    MAX_MODULES,
    SubmissionNotFound,
    SubmissionRefused,
    check,
    locate,
    read_untrusted,
    stage,
)

REPO = Path(__file__).resolve().parents[2]
COURSE = REPO / "tests" / "fixtures" / "mini_course"
SOLUTION = COURSE / "assignments" / "shout" / "solution" / "shouter.py"


def _submission(tmp_path: Path, name: str = "sub") -> Path:
    folder = tmp_path / name
    folder.mkdir()
    shutil.copy(SOLUTION, folder / "shouter.py")
    return folder


def test_a_regular_submission_is_staged_with_its_modules(tmp_path):
    folder = _submission(tmp_path)
    (folder / "helper.py").write_text("X = 1\n")
    (folder / "notes.txt").write_text("not python\n")
    staged = stage(folder / "shouter.py", "shouter.py", tmp_path / "staged")
    assert sorted(p.name for p in staged.parent.iterdir()) == ["helper.py", "shouter.py"]
    assert staged.read_bytes() == SOLUTION.read_bytes()
    assert not any(p.is_symlink() for p in staged.parent.iterdir())


def _linked_node(folder: Path, target: str) -> None:
    (folder / "shouter.py").unlink()
    (folder / "shouter.py").symlink_to(target)


@pytest.mark.parametrize(("make", "expected"), [
    (lambda f: _linked_node(f, str(SOLUTION)), "shouter.py is a symbolic link"),
    (lambda f: _linked_node(f, "/dev/zero"), "shouter.py is a symbolic link"),
    (lambda f: _linked_node(f, "/nonexistent"), "shouter.py is a symbolic link"),
    (lambda f: (f / "leak.py").symlink_to("/etc/shadow"), "leak.py is a symbolic link"),
    (lambda f: (f / "other.py").symlink_to(SOLUTION), "other.py is a symbolic link"),
    (lambda f: ((f / "shouter.py").unlink(), os.mkfifo(f / "shouter.py")),
     "shouter.py is a FIFO"),
    (lambda f: os.mkfifo(f / "pipe.py"), "pipe.py is a FIFO"),
    (lambda f: (f / "big.py").write_bytes(b"#" * (MAX_FILE_BYTES + 1)),
     "big.py is larger than"),
    (lambda f: [(f / f"m{i}.py").write_text("") for i in range(MAX_MODULES + 1)],
     "Python files beside your node"),
])
def test_what_the_grader_will_not_read_is_refused_by_name(tmp_path, make, expected):
    folder = _submission(tmp_path)
    make(folder)
    with pytest.raises(SubmissionRefused, match=expected):
        check(folder, "shouter.py")
    with pytest.raises(SubmissionRefused, match=expected):
        stage(folder / "shouter.py", "shouter.py", tmp_path / "staged")
    assert not any((tmp_path / "staged").glob("*")) if (tmp_path / "staged").exists() else True


def test_a_device_given_as_the_node_is_refused():
    with pytest.raises(SubmissionRefused, match="zero is a device"):
        check(Path("/dev/zero"), "shouter.py")


@pytest.mark.parametrize("command", ["check", "grade"])
def test_the_cli_refuses_a_linked_submission_as_the_students_error(tmp_path, monkeypatch,
                                                                   command):
    """Exit 2 and one plain line, before any grading: never "the autograder failed"."""
    monkeypatch.setenv("AUTOGRADER_COURSE", str(COURSE))
    folder = _submission(tmp_path)
    (folder / "leak.py").symlink_to("/etc/shadow")
    result = CliRunner().invoke(main, [command, "shout", str(folder)])
    assert result.exit_code == 2, result.output
    assert "leak.py is a symbolic link: submit the file itself" in result.output
    assert "autograder failed" not in result.output


def test_a_fifo_as_the_node_does_not_hang_the_cli(tmp_path, monkeypatch):
    monkeypatch.setenv("AUTOGRADER_COURSE", str(COURSE))
    folder = _submission(tmp_path)
    (folder / "shouter.py").unlink()
    os.mkfifo(folder / "shouter.py")  # opening it for reading would block without O_NONBLOCK
    result = CliRunner().invoke(main, ["check", "shout", str(folder)])
    assert result.exit_code == 2
    assert "shouter.py is a FIFO, not a regular file" in result.output


def test_the_node_file_is_found_in_the_folder_or_the_one_sub_folder_holding_it(
        tmp_path: Path) -> None:
    (tmp_path / "a" / "deep").mkdir(parents=True)
    (tmp_path / "a" / "deep" / "shouter.py").write_text("")
    assert locate(tmp_path, "shouter.py") == tmp_path / "a" / "deep" / "shouter.py"
    (tmp_path / "shouter.py").write_text("")
    assert locate(tmp_path, "shouter.py") == tmp_path / "shouter.py"  # the top one first
    assert locate(tmp_path / "shouter.py", "other.py") == tmp_path / "shouter.py"


def test_no_file_or_two_candidates_are_not_found(tmp_path: Path) -> None:
    with pytest.raises(SubmissionNotFound, match="does not exist"):
        locate(tmp_path / "missing.py", "shouter.py")
    for folder in ("one", "two"):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "shouter.py").write_text("")
    with pytest.raises(SubmissionNotFound, match="holds no shouter.py"):
        locate(tmp_path, "shouter.py")


def test_a_linked_folder_is_not_entered(tmp_path: Path) -> None:
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "shouter.py").write_text("")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "link").symlink_to(elsewhere)
    with pytest.raises(SubmissionNotFound):
        locate(tmp_path / "sub", "shouter.py")


def test_a_file_is_read_up_to_its_bound(tmp_path: Path) -> None:
    path = tmp_path / "node.py"
    path.write_bytes(b"x" * 100)
    assert read_untrusted(path, limit=100) == b"x" * 100
    with pytest.raises(SubmissionRefused, match="node.py is larger than 0 KB"):
        read_untrusted(path, limit=99)
    with pytest.raises(SubmissionRefused, match="is a folder, not a regular file"):
        read_untrusted(tmp_path)
