"""grade-batch: a folder of 12 submissions, good, bad and broken, two at a time; the same
scores as one by one; resumable after being killed halfway; sharded and merged."""

from __future__ import annotations

import contextlib
import csv
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import pytest
from mini_class import COURSE, EXPECTED, KINDS, VARIANTS

from autograder.commands.batch import in_shard
from autograder.core.exercise import find_exercise
from autograder.core.settings import RunSettings
from autograder.grading.run import grade

pytestmark = pytest.mark.slow

TESTS = 3  # in the shout exercise's public and hidden tests



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
def one_by_one(tmp_path_factory, course_env) -> dict[str, str]:
    """Each student's score graded alone: each of the five programs graded once, alone (a
    student's score is its program's; the class holds each program two or more times)."""
    exercise = find_exercise("shout")
    folder = tmp_path_factory.mktemp("one-by-one")
    by_kind = {}
    for kind in sorted(set(KINDS)):
        (folder / kind).mkdir()
        (folder / kind / "shouter.py").write_text(VARIANTS[kind])
        result = grade(exercise, folder / kind)
        assert result.grader_error is None, result.grader_details
        by_kind[kind] = str(result.score)
    return {f"student{i:02d}": by_kind[kind] for i, kind in enumerate(KINDS)}


def batch(args: list[str], env: dict[str, str], **kwargs) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "autograder.cli", "grade-batch", *args],
                            env=env, start_new_session=True, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, **kwargs)


def rows(path: Path) -> dict[str, dict[str, str]]:
    with path.open() as fh:
        return {row["student"]: row for row in csv.DictReader(fh)}




def test_one_by_one_scores_good_bad_and_broken(one_by_one):
    assert one_by_one == {f"student{i:02d}": EXPECTED[kind] for i, kind in enumerate(KINDS)}


def test_batch_at_auto_matches_one_by_one(tmp_path, submissions, one_by_one, course_env):
    book = tmp_path / "gradebook.csv"
    proc = batch(["shout", str(submissions), "--jobs", "auto", "--csv", str(book),
                  "--out", str(tmp_path / "reports")], course_env)
    output, _ = proc.communicate(timeout=600)
    assert proc.returncode == 0, output
    assert re.search(r"--jobs auto: \d+ gradings? at a time\. ", output), output
    assert {s: r["score"] for s, r in rows(book).items()} == one_by_one


def _processes() -> dict[int, tuple[int, str]]:
    """Every process: pid -> (parent pid, start time), from /proc."""
    found = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        fields = stat.rsplit(")", 1)[1].split()
        found[int(entry.name)] = (int(fields[1]), fields[19])
    return found


def run_folders(processes: set[tuple[int, str]]) -> set[Path]:
    """The temporary folders of the gradings among ``processes`` (their pytest children):
    an exec'd child names its settings on its command line; one forked from the grader's
    template (whose command line it shows) works in its folder, beside its log."""
    found = set()
    for pid, _start in processes:
        try:
            args = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
            cwd = Path(os.readlink(f"/proc/{pid}/cwd"))
        except OSError:
            continue
        if b"--autograder-settings" in args:
            settings = RunSettings.from_json(args[args.index(b"--autograder-settings") + 1])
            found.add(Path(settings.report).parent)
        elif b"autograder.grading.template" in args and (cwd / "pytest.log").exists():
            found.add(cwd)
    return found


def count_done(folder: Path) -> int:
    """How many tests a grading's pytest child has ended so far (its progress characters)."""
    log = folder / "pytest.log"
    text = log.read_text() if log.exists() else ""
    return sum(len(m) for m in re.findall(r"^([.FEsxX]+)(?=\s*(?:\[\s*\d+%\])?$)", text, re.M))


def descendants(pid: int) -> set[tuple[int, str]]:
    """The processes below ``pid`` (with their start times, so a reused pid is not them)."""
    table = _processes()
    found, frontier = set(), {pid}
    while frontier:
        frontier = {p for p, (parent, _t) in table.items() if parent in frontier}
        found |= {(p, table[p][1]) for p in frontier}
    return found


def signal_all(processes: set[tuple[int, str]], sig: int) -> None:
    for pid, _start in processes:
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, sig)


def alive(processes: set[tuple[int, str]]) -> set[tuple[int, str]]:
    table = _processes()
    return {(p, t) for p, t in processes if p in table and table[p][1] == t}


@pytest.fixture(scope="module")
def resumed(tmp_path_factory, submissions, course_env) -> SimpleNamespace:
    """The class graded two at a time, killed with SIGKILL part-way, then run again: the
    second run's output, the gradebook and the reports, and who was graded before the
    kill. Killed, the batch leaves no grading running (each run's child sees its
    lifeline close and ends itself and its student processes)."""
    tmp_path = tmp_path_factory.mktemp("resumed")
    book, out = tmp_path / "gradebook.csv", tmp_path / "reports"
    args = ["shout", str(submissions), "--jobs", "2", "--csv", str(book), "--out", str(out)]
    first = batch(args, course_env)
    deadline = time.monotonic() + 300
    # Once four students are graded and a grading is seen part-way (tests left to run),
    # freeze the batch, so that what each grading had done when it died is known exactly.
    # If the part-way one finished its tests just before the freeze (the kill would then
    # prove nothing), let the batch go on and look again; a grading with all its tests
    # done has its verdict, so the pause changes no score. Then kill the batch and thaw
    # the gradings: each must end without running on.
    while True:
        assert time.monotonic() < deadline, "no grading was ever caught part-way"
        assert first.poll() is None, first.stdout.read()
        if len(list(out.glob("*/results.json"))) >= 4:
            running = descendants(first.pid)
            if any(count_done(folder) < TESTS for folder in run_folders(running)):
                signal_all(running, signal.SIGSTOP)
                folders = {folder: count_done(folder) for folder in run_folders(running)}
                if any(done < TESTS for done in folders.values()):
                    break
                signal_all(running, signal.SIGCONT)
        time.sleep(0.2)
    os.killpg(first.pid, signal.SIGKILL)
    first.wait()
    signal_all(running, signal.SIGCONT)
    deadline = time.monotonic() + 60
    while alive(running) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not alive(running), f"left running after the batch was killed: {alive(running)}"
    # The lifeline's watcher and the run's own thread wake together: the test in flight may
    # still end (and, after the last test, the summary be printed) before the kill lands,
    # but no grading goes on to another test.
    for folder, done in folders.items():  # the dead batch could not remove them
        assert count_done(folder) <= done + 1, (folder / "pytest.log").read_text()[-2000:]
        shutil.rmtree(folder, ignore_errors=True)
    done_before = {p.parent.name for p in out.glob("*/results.json")}
    assert 4 <= len(done_before) < len(KINDS)
    second = batch(args, course_env)
    output, _ = second.communicate(timeout=600)
    assert second.returncode == 0, output
    return SimpleNamespace(output=output, book=book, out=out, done_before=done_before)


def test_batch_resumes_after_being_killed(resumed, one_by_one):
    for student in resumed.done_before:
        assert f"{student}: already graded" in resumed.output
    assert {s: r["score"] for s, r in rows(resumed.book).items()} == one_by_one


def test_batch_with_two_jobs_matches_one_by_one(resumed, one_by_one):
    """The gradebook and reports of the class graded two at a time (the resumed batch's:
    what a killed and resumed batch writes is what one run writes)."""
    graded = rows(resumed.book)
    assert {s: r["score"] for s, r in graded.items()} == one_by_one
    assert all(r["max_score"] == "3" for r in graded.values())
    assert {r["passed"] for r in graded.values()} == {"yes", "no"}
    assert "shout:test_upper_case" in next(iter(graded.values()))
    assert (resumed.out / "student00" / "report.html").exists()
    assert (resumed.out / "student00" / "gradescope.json").exists()
    assert "RuntimeError: boom" in (resumed.out / "student04" / "output.log").read_text()




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
    # A frozen copy of the project's quizzes: editing quizzes/ leaves this test alone.
    env["AUTOGRADER_COURSE"] = str(Path(__file__).parents[1] / "fixtures" / "quiz_course")
    answers = tmp_path / "answers"
    answers.mkdir()
    key = subprocess.run([sys.executable, "-m", "autograder.cli", "quiz", "key", "rclpy-part2"],
                         capture_output=True, text=True, check=True, env=env).stdout
    (answers / "amna.json").write_text(key)
    (answers / "bilal.json").write_text('{"quiz": "rclpy-part2", "answers": {}}')
    book = tmp_path / "gradebook.csv"
    book.write_text("student,item,score,max_score,passed\namna,shout,3,3,yes\n")
    proc = batch(["rclpy-part2", str(answers), "--csv", str(book), "--out",
                  str(tmp_path / "q")], env, cwd=Path(__file__).parents[2])
    output, _ = proc.communicate(timeout=120)
    assert proc.returncode == 0, output
    assert "--jobs auto" not in output  # the default, auto, scores a quiz one at a time
    with book.open() as fh:
        got = {(r["student"], r["item"]): (r["score"], r["passed"]) for r in csv.DictReader(fh)}
    assert got == {("amna", "shout"): ("3", "yes"), ("amna", "rclpy-part2"): ("5", "yes"),
                   ("bilal", "rclpy-part2"): ("0", "no")}

