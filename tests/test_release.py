"""What students get leaks nothing; the Gradescope bundle grades end to end."""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from autograder.commands.release import build_gradescope_bundle, build_release, student_files
from autograder.core.exercise import list_exercises

ROOT = Path(__file__).resolve().parent.parent


def hidden_test_names(exercise) -> set[str]:
    names = set()
    for path in exercise.hidden_tests.rglob("*.py"):
        tree = ast.parse(path.read_text())
        names |= {node.name for node in ast.walk(tree)
                  if isinstance(node, ast.FunctionDef) and node.name.startswith("test_")}
    return names


def solution_lines(exercise) -> set[str]:
    """Lines of the reference solution that nothing a student is meant to have shows (the
    starter, the READMEs, which may teach a pattern on purpose, the public tests)."""
    published = "".join(p.read_text(errors="replace") for p in student_files(exercise))
    lines = set()
    for path in exercise.solution.parent.rglob("*.py"):
        for line in path.read_text().splitlines():
            line = line.strip()
            if len(line) >= 24 and line not in published and not line.startswith("#"):
                lines.add(line)
    return lines


@pytest.fixture(scope="module")
def release(tmp_path_factory) -> Path:
    return build_release(tmp_path_factory.mktemp("r") / "release")


def test_release_has_what_students_need(release):
    for exercise in list_exercises():
        folder = release / "assignments" / exercise.id
        assert (folder / "exercise.yaml").exists()
        assert (folder / "starter" / exercise.file).exists()
        assert (folder / "README.md").exists() and (folder / "README.ur.md").exists()
        assert any((folder / "tests" / "public").glob("test_*.py"))
    assert (release / "autograder" / "cli" / "__init__.py").exists()
    assert (release / "pyproject.toml").exists()
    assert (release / "quizzes-rendered" / "rclpy-part2.ur.html").exists()


def test_release_leaks_no_hidden_test_solution_or_key(release):
    assert not list(release.rglob("solution")) and not list(release.rglob("hidden"))
    assert not list(release.glob("quizzes/*.yaml"))  # quiz files hold the answer key
    catalogs = "".join(p.read_text() for p in (release / "locales").rglob("*.po*"))
    assert "/tests/hidden/" not in catalogs  # hidden tests' feedback is not shipped
    leaks = []
    for exercise in list_exercises():
        names, lines = hidden_test_names(exercise), solution_lines(exercise)
        assert names and lines  # the check has something to look for
        for path in (release / "assignments" / exercise.id).rglob("*"):
            if path.is_file():
                text = path.read_text(errors="replace")
                leaks += [(path, n) for n in names | lines if n in text]
    assert leaks == []


def test_student_files_leave_out_solution_and_hidden_tests():
    for exercise in list_exercises():
        for path in student_files(exercise):
            assert not path.is_relative_to(exercise.folder / "solution")
            assert not path.is_relative_to(exercise.hidden_tests)


@pytest.mark.slow
def test_gradescope_bundle_grades_a_submission(tmp_path):
    exercise = next(e for e in list_exercises() if e.id == "parameter_validation")
    bundle = build_gradescope_bundle(exercise, tmp_path / "autograder.zip")
    root = tmp_path / "autograder"  # a fake /autograder tree
    with zipfile.ZipFile(bundle) as zf:
        names = zf.namelist()
        assert {"setup.sh", "run_autograder"} <= set(names)
        assert not [n for n in names if "/solution/" in n]
        assert any("/tests/hidden/" in n for n in names)
        zf.extractall(root / "source-zip")
    (root / "source").symlink_to(root / "source-zip" / "source")
    (root / "submission").mkdir()
    (root / "submission" / exercise.file).write_text(exercise.starter.read_text())
    run = root / "source-zip" / "run_autograder"
    env = dict(os.environ, AUTOGRADER_ROOT=str(root), AUTOGRADER_VENV=sys.prefix)
    env.pop("AUTOGRADER_COURSE", None)
    done = subprocess.run(["bash", str(run)], env=env, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    results = json.loads((root / "results" / "results.json").read_text())
    assert 0 < results["score"] < 13
    assert len(results["tests"]) == 11
    assert {t["visibility"] for t in results["tests"]} == {"visible", "after_published"}
    assert sum(t["max_score"] for t in results["tests"]) == 13
