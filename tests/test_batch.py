"""grade-batch: a folder of 12 submissions, good, bad and broken, two at a time; the same
scores as one by one; resumable after being killed halfway; sharded and merged."""

from __future__ import annotations

import csv
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from autograder.batch import in_shard
from autograder.exercise import find_exercise
from autograder.grading import grade

pytestmark = pytest.mark.slow

COURSE = Path(__file__).parent / "fixtures" / "mini_course"
SOLUTION = (COURSE / "assignments/shout/solution/shouter.py").read_text()
VARIANTS = {
    "good": SOLUTION,
    "lower": SOLUTION.replace("msg.data.upper()", "msg.data"),
    "double": SOLUTION.replace("        self.pub.publish(String(data=msg.data.upper()))",
                               "        for _ in range(2):\n"
                               "            self.pub.publish(String(data=msg.data.upper()))"),
    "syntax": SOLUTION.replace("def on_words(self, msg):", "def on_words(self, msg)"),
    "crash": SOLUTION.replace("super().__init__('shouter')", "raise RuntimeError('boom')"),
}
KINDS = ["good", "lower", "double", "syntax", "crash", "good", "lower", "good", "double",
         "crash", "good", "syntax"]


@pytest.fixture(scope="module")
def course_env():
    old = os.environ.get("AUTOGRADER_COURSE")
    os.environ["AUTOGRADER_COURSE"] = str(COURSE)
    yield dict(os.environ)
    if old is None:
        del os.environ["AUTOGRADER_COURSE"]
    else:
        os.environ["AUTOGRADER_COURSE"] = old


@pytest.fixture(scope="module")
def submissions(tmp_path_factory, course_env) -> Path:
    folder = tmp_path_factory.mktemp("submissions")
    for i, kind in enumerate(KINDS):
        if i % 2:  # half as a student's folder, half as a bare file
            (folder / f"student{i:02d}").mkdir()
            (folder / f"student{i:02d}" / "shouter.py").write_text(VARIANTS[kind])
        else:
            (folder / f"student{i:02d}.py").write_text(VARIANTS[kind])
    return folder


@pytest.fixture(scope="module")
def one_by_one(submissions) -> dict[str, str]:
    exercise = find_exercise("shout")
    scores = {}
    for entry in sorted(submissions.iterdir()):
        result = grade(exercise, entry)
        assert result.grader_error is None, result.grader_details
        scores[entry.stem] = str(result.score)
    return scores


def batch(args: list[str], env: dict[str, str], **kwargs) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "autograder.cli", "grade-batch", *args],
                            env=env, start_new_session=True, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, **kwargs)


def rows(path: Path) -> dict[str, dict[str, str]]:
    with path.open() as fh:
        return {row["student"]: row for row in csv.DictReader(fh)}


EXPECTED = {"good": "3", "lower": "2", "double": "2", "syntax": "0", "crash": "0"}


def test_one_by_one_scores_good_bad_and_broken(one_by_one):
    assert one_by_one == {f"student{i:02d}": EXPECTED[kind] for i, kind in enumerate(KINDS)}


def test_batch_with_two_jobs_matches_one_by_one(tmp_path, submissions, one_by_one, course_env):
    book, out = tmp_path / "gradebook.csv", tmp_path / "reports"
    proc = batch(["shout", str(submissions), "--jobs", "2", "--csv", str(book),
                  "--out", str(out)], course_env)
    output, _ = proc.communicate(timeout=600)
    assert proc.returncode == 0, output
    graded = rows(book)
    assert {s: r["score"] for s, r in graded.items()} == one_by_one
    assert all(r["max_score"] == "3" for r in graded.values())
    assert {r["passed"] for r in graded.values()} == {"yes", "no"}
    assert "shout:test_upper_case" in next(iter(graded.values()))
    assert (out / "student00" / "report.html").exists()
    assert (out / "student00" / "gradescope.json").exists()
    assert "RuntimeError: boom" in (out / "student04" / "output.log").read_text()  # crash


def test_batch_resumes_after_being_killed(tmp_path, submissions, one_by_one, course_env):
    book, out = tmp_path / "gradebook.csv", tmp_path / "reports"
    args = ["shout", str(submissions), "--jobs", "2", "--csv", str(book), "--out", str(out)]
    first = batch(args, course_env)
    deadline = time.monotonic() + 300
    while len(list(out.glob("*/results.json"))) < 4 and time.monotonic() < deadline:
        assert first.poll() is None, first.stdout.read()
        time.sleep(0.2)
    os.killpg(first.pid, signal.SIGKILL)
    first.wait()
    done_before = {p.parent.name for p in out.glob("*/results.json")}
    assert 4 <= len(done_before) < len(KINDS)
    second = batch(args, course_env)
    output, _ = second.communicate(timeout=600)
    assert second.returncode == 0, output
    for student in done_before:
        assert f"{student}: already graded" in output
    assert {s: r["score"] for s, r in rows(book).items()} == one_by_one


def test_shards_partition_and_merge(tmp_path, submissions, one_by_one, course_env):
    students = sorted(one_by_one)
    shares = [[s for s in students if in_shard(s, (i, 3))] for i in (1, 2, 3)]
    assert sorted(sum(shares, [])) == students
    assert all(in_shard(s, (1, 1)) for s in students)
    # Half the class is enough to see shards split and merge (and costs half the gradings).
    half = tmp_path / "half"
    half.mkdir()
    for entry in sorted(submissions.iterdir())[:6]:
        (shutil.copytree if entry.is_dir() else shutil.copy)(entry, half / entry.name)
    shares = [[s for s in share if (half / s).exists() or (half / f"{s}.py").exists()]
              for share in shares]
    books = []
    for i in (1, 2):  # two shards of three are enough to see the merge
        book = tmp_path / f"shard{i}.csv"
        proc = batch(["shout", str(half), "--jobs", "2", "--csv", str(book),
                      "--out", str(tmp_path / f"out{i}"), "--shard", f"{i}/3"], course_env)
        output, _ = proc.communicate(timeout=600)
        assert proc.returncode == 0, output
        assert set(rows(book)) == set(shares[i - 1])
        books.append(book)
    merged = tmp_path / "merged.csv"
    subprocess.run([sys.executable, "-m", "autograder.cli", "gradebook", "merge", str(merged),
                    *map(str, books)], check=True, env=course_env)
    assert {s: r["score"] for s, r in rows(merged).items()} == {
        s: one_by_one[s] for s in shares[0] + shares[1]}


def test_quiz_answers_go_into_the_same_gradebook(tmp_path, course_env):
    env = dict(course_env)
    del env["AUTOGRADER_COURSE"]  # the project's own quizzes
    answers = tmp_path / "answers"
    answers.mkdir()
    key = subprocess.run([sys.executable, "-m", "autograder.cli", "quiz", "key", "rclpy-part2"],
                         capture_output=True, text=True, check=True, env=env).stdout
    (answers / "amna.json").write_text(key)
    (answers / "bilal.json").write_text('{"quiz": "rclpy-part2", "answers": {}}')
    book = tmp_path / "gradebook.csv"
    book.write_text("student,item,score,max_score,passed\namna,shout,3,3,yes\n")
    proc = batch(["rclpy-part2", str(answers), "--csv", str(book), "--out",
                  str(tmp_path / "q")], env, cwd=Path(__file__).parent.parent)
    output, _ = proc.communicate(timeout=120)
    assert proc.returncode == 0, output
    with book.open() as fh:
        got = {(r["student"], r["item"]): (r["score"], r["passed"]) for r in csv.DictReader(fh)}
    assert got == {("amna", "shout"): ("3", "yes"), ("amna", "rclpy-part2"): ("5", "yes"),
                   ("bilal", "rclpy-part2"): ("0", "no")}

