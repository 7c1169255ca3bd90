"""Official grades in the shape Gradescope and Kubernetes grade in: root in a container
without namespaces (no ``CAP_SYS_ADMIN``) and without a writable cgroup filesystem (issue
29). The shape is made here as the issue describes it: a private mount namespace with an
empty read-only tmpfs over ``/sys/fs/cgroup``, and ``setpriv`` dropping ``CAP_SYS_ADMIN``
from the bounding set. In it the Gradescope bundle's ``setup.sh`` and ``run_autograder``
run exactly as shipped, and ``grade-batch`` grades a class as the Kubernetes Job does; the
hostile corpus tries to read the hidden tests, another student's files, change a result
and leave something running. Isolation by user must stop each, and the references keep
full marks."""

from __future__ import annotations

import json
import os
import re
import shutil
import stat
import subprocess
import tempfile
import zipfile
from collections.abc import Iterator
from pathlib import Path

import pytest
from shapes import DOCKER_CAPS, POD_CAPS, clean_env, container, world_readable_folder

from autograder.core.exercise import find_exercise
from autograder.sandbox.sweep import STUDENT_UID_BASE, user_ipc, user_processes

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(os.geteuid() != 0 or not shutil.which("setpriv")
                       or not shutil.which("unshare") or not Path("/usr/bin/python3").exists(),
                       reason="needs root, setpriv, unshare and /usr/bin/python3"),
]

REPO = Path(__file__).resolve().parent.parent
MINI = REPO / "tests" / "fixtures" / "mini_course"
CORPUS = REPO / "tests" / "submissions" / "hostile"
SOLUTION = MINI / "assignments" / "shout" / "solution"
CONTAINER = container(DOCKER_CAPS)
POD = container(POD_CAPS)
# Gradescope's image has its Python in /usr/bin, readable by every user.
PATH = f"/usr/bin:/bin:{os.environ.get('PATH', '')}"


def _left_running(uids: list[int]) -> list[int]:
    """The processes of a run's student users still running (other gradings on the
    machine have users of their own)."""
    return [pid for uid in uids for pid in user_processes(uid)]


@pytest.fixture(scope="module")
def course() -> Iterator[Path]:
    """A course of the platform and the mini course's `shout` exercise, as an instructor's
    checkout would be: the bundle is built from it."""
    folder = world_readable_folder("autograder-course-")
    for name in ("pyproject.toml", "README.md", "tasks.py", "Makefile", "babel.cfg",
                 "autograder", "content", "sim", "locales"):
        source = REPO / name
        if source.is_dir():
            shutil.copytree(source, folder / name,
                            ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        else:
            shutil.copy2(source, folder / name)
    shutil.copytree(MINI / "assignments", folder / "assignments")
    yield folder
    shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture(scope="module")
def gradescope(course: Path) -> Iterator[Path]:
    """/autograder as Gradescope lays it: the bundle unzipped into source/, then setup.sh
    run as shipped (in the container shape, from Gradescope's /usr/bin/python3)."""
    from autograder.commands.release import build_gradescope_bundle

    root = world_readable_folder("autograder-gs-")
    old = os.environ.get("AUTOGRADER_COURSE")
    os.environ["AUTOGRADER_COURSE"] = str(course)
    try:
        bundle = build_gradescope_bundle(find_exercise("shout"), root / "autograder.zip")
    finally:
        if old is None:
            os.environ.pop("AUTOGRADER_COURSE", None)
        else:
            os.environ["AUTOGRADER_COURSE"] = old
    with zipfile.ZipFile(bundle) as zf:
        zf.extractall(root)
    for script in ("setup.sh", "run_autograder"):
        (root / script).chmod(0o755)
    env = {**_clean_env(), "AUTOGRADER_ROOT": str(root)}
    setup = subprocess.run([*CONTAINER, "bash", str(root / "setup.sh")], env=env,
                           capture_output=True, text=True, timeout=1200, cwd=root)
    assert setup.returncode == 0, setup.stdout[-3000:] + setup.stderr[-3000:]
    yield root
    shutil.rmtree(root, ignore_errors=True)


def _clean_env() -> dict[str, str]:
    return clean_env(PATH)


def _run_autograder(root: Path, submission: Path) -> tuple[dict, str]:
    """One submission through run_autograder, as Gradescope runs it: its results.json
    and our log of the programs' output."""
    target = root / "submission"
    shutil.rmtree(target, ignore_errors=True)
    shutil.copytree(submission, target)
    shutil.rmtree(root / "results", ignore_errors=True)
    env = {**_clean_env(), "AUTOGRADER_ROOT": str(root)}
    done = subprocess.run([*CONTAINER, str(root / "run_autograder")], env=env,
                          capture_output=True, text=True, timeout=600, cwd=root)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    results = json.loads((root / "results" / "results.json").read_text())
    log = root / "results" / "ours.log"
    return results, log.read_text(errors="replace") if log.exists() else ""


def _ours(root: Path) -> dict:
    return json.loads((root / "results" / "ours.json").read_text())


def _uids(root: Path) -> list[int]:
    """The student users of the last run_autograder's grading."""
    uids = _ours(root)["isolation"]["student_uids"]
    assert uids and all(uid >= STUDENT_UID_BASE for uid in uids)
    return uids


def test_the_reference_keeps_full_marks_as_an_official_grade(gradescope):
    results, _log = _run_autograder(gradescope, SOLUTION)
    assert results["score"] == 3, results
    isolation = _ours(gradescope)["isolation"]
    assert isolation["mode"] == "user" and isolation["official"] is True
    assert isolation["reason"] == "namespaces are not allowed here (an unprivileged container?)"
    assert isolation["bounds"]["cgroup"] is None  # the container's cgroups are read-only
    assert _left_running(_uids(gradescope)) == []


def test_no_hidden_test_or_solution_is_read(gradescope):
    results, log = _run_autograder(gradescope, CORPUS / "reads_secrets")
    assert results["score"] == 3
    assert "SECRETS FOUND" in log
    assert not [line for line in log.splitlines()
                if line.startswith("SECRET ") and str(gradescope) in line]
    # and the grader closed what the mount namespace would have hidden
    for folder in ("assignments",):
        assert not (gradescope / "source" / folder).stat().st_mode & 0o007


def test_a_daemon_cannot_rewrite_the_results_and_nothing_is_left(gradescope):
    results, log = _run_autograder(gradescope, CORPUS / "rewrites_results")
    assert "REWROTE" not in log
    assert results["score"] == 3 and "FORGED" not in json.dumps(results)
    # the daemon went with the program: nothing is left to write
    assert _left_running(_uids(gradescope)) == []
    assert json.loads((gradescope / "results" / "results.json").read_text()) == results


def test_modules_beside_the_node_never_run_as_root(gradescope):
    results, log = _run_autograder(gradescope, CORPUS / "shadows_stdlib")
    assert results["score"] == 3
    assert "ROOT CODE RAN" not in log
    uids = {int(uid) for uid in re.findall(r"^NODE RUNS AS UID (\d+)$", log, re.M)}
    assert uids and all(uid >= STUDENT_UID_BASE for uid in uids)


def test_ipc_objects_and_scratch_files_are_swept(gradescope):
    results, log = _run_autograder(gradescope, CORPUS / "ipc_leftovers")
    assert results["score"] == 3
    names = re.findall(r"^FILE LEFT (\S+)", log, re.M)
    assert names, "it left files in the shared scratch folders"
    assert not [name for name in names if Path(name).exists()]
    for uid in _uids(gradescope):
        assert user_ipc(uid) == []
    assert _left_running(_uids(gradescope)) == []


def test_the_graders_processes_can_be_seen_but_not_stopped_or_traced(gradescope):
    """Without a PID namespace or a /proc of its own the program lists the machine's
    processes, command lines included; another user's it can neither stop, trace nor read
    the memory of: the report's key stays the grader's."""
    results, log = _run_autograder(gradescope, CORPUS / "snoops_processes")
    assert results["score"] == 3
    assert re.search(r"^PROCESSES SEEN \d+ FOREIGN [1-9]\d* STOPPED 0$", log, re.M), log[-2000:]
    assert "TRACED 0" in log
    assert "NoNewPrivs:\t1" in log


@pytest.fixture(scope="module")
def venv(gradescope: Path) -> Path:
    return gradescope / "venv"


def test_a_batch_keeps_each_students_files_from_the_others(gradescope, venv, course):
    """The Kubernetes Job's command: grade-batch over a class folder, in the same shape.
    Students cannot read each other's submissions or reports, and every grade is
    official."""
    work = world_readable_folder("autograder-k8s-")
    try:
        submissions = work / "submissions"
        for name, source in (("alice", CORPUS / "reads_classmates"), ("bob", SOLUTION),
                             ("carol", CORPUS / "reads_secrets")):
            shutil.copytree(source, submissions / name)
        # as a claim mounted into a pod holds them: readable by all until the grader closes
        for path in [submissions, *submissions.rglob("*")]:
            path.chmod(0o755 if path.is_dir() else 0o644)
        out = work / "out"
        env = {**_clean_env(), "AUTOGRADER_COURSE": str(gradescope / "source")}
        done = subprocess.run(
            [*POD, str(venv / "bin" / "autograder"), "grade-batch", "shout",
             str(submissions), "--csv", str(out / "gradebook.csv"), "--out", str(out),
             "--jobs", "2"], env=env, capture_output=True, text=True, timeout=900, cwd=work)
        assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
        results = {name: json.loads((out / name / "results.json").read_text())
                   for name in ("alice", "bob", "carol")}
        assert all(r["score"] == 3 for r in results.values()), results
        assert all(r["isolation"]["mode"] == "user" and r["isolation"]["official"]
                   for r in results.values())
        alice = (out / "alice" / "output.log").read_text(errors="replace")
        assert "CLASSMATES READ:" in alice  # it looked (copies elsewhere are not the class)
        assert not [line for line in alice.splitlines()
                    if line.startswith("CLASSMATE ") and str(work) in line]
        carol = (out / "carol" / "output.log").read_text(errors="replace")
        assert not [line for line in carol.splitlines()
                    if line.startswith("SECRET ") and str(gradescope) in line]
        assert not submissions.stat().st_mode & 0o007
        assert not out.stat().st_mode & 0o007
        uids = {uid for r in results.values() for uid in r["isolation"]["student_uids"]}
        assert _left_running(sorted(uids)) == []
    finally:
        shutil.rmtree(work, ignore_errors=True)


def test_an_ordinary_user_grade_is_labelled_and_recipes_refuse_it(gradescope, venv):
    """Where the student would run as the grader's user, run_autograder's grade is refused
    as the grader's failure, and grade-batch refuses without --allow-unofficial."""
    nobody = {**_clean_env(), "AUTOGRADER_COURSE": str(gradescope / "source"),
              "HOME": "/tmp", "AUTOGRADER_ISOLATION": "basic"}
    refused = subprocess.run(
        [str(venv / "bin" / "autograder"), "grade", "shout", str(SOLUTION),
         "--require-official"], env=nobody, capture_output=True, text=True, timeout=300,
        cwd="/")
    assert refused.returncode == 3
    assert "cannot give official grades" in refused.stdout + refused.stderr
    with tempfile.TemporaryDirectory() as tmp:
        batch = subprocess.run(
            [str(venv / "bin" / "autograder"), "grade-batch", "shout", str(SOLUTION.parent),
             "--csv", f"{tmp}/g.csv", "--out", f"{tmp}/out"], env=nobody,
            capture_output=True, text=True, timeout=300, cwd="/")
    assert batch.returncode == 3
    assert "--allow-unofficial" in batch.stdout + batch.stderr
    shown = subprocess.run(
        [str(venv / "bin" / "autograder"), "grade", "shout", str(SOLUTION), "--results",
         f"{gradescope}/unofficial.json"], env=nobody, capture_output=True, text=True,
        timeout=300, cwd="/")
    assert shown.returncode == 0, shown.stderr
    assert "this grade is not official" in shown.stdout
    data = json.loads((gradescope / "unofficial.json").read_text())
    assert data["isolation"]["official"] is False and data["score"] == 3
    assert stat.S_ISREG((gradescope / "unofficial.json").stat().st_mode)
