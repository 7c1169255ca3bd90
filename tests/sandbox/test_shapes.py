"""The hostile corpus in each shape the grader meets besides strict isolation (issue 29;
strict is tests/sandbox/test_hostile.py): root in a container without namespaces (Docker's
capabilities: isolation by user, official), the same container without CAP_SETUID (basic
isolation as root) and an ordinary user (basic). In each, ``grade-batch`` grades the
shape's programs two at a time, as a course grades a class: the whole corpus in the
container; in the two basic shapes, every program whose outcome a basic shape can change
(``SAME_IN_EVERY_SHAPE`` says which are left out, and why).

Every program, in every shape it is graded in, ends with a score, a message and a results
file, labelled with the shape's isolation and whether the grade is official. Where the
README's threat model table says a shape stops an attack, a test here tries it in that
shape. In the two basic shapes the student is the grader's user: the programs that act on
whatever the grader's user runs (stopping, joining or starving other gradings) are graded
alone there, since what they do to a classmate's grading (or, left running, to the next
one) is what basic isolation does not stop."""

from __future__ import annotations

import dataclasses
import json
import os
import re
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from shapes import (
    DOCKER_CAPS,
    NO_SETUID_CAPS,
    NOBODY,
    clean_env,
    container,
    ordinary_user,
    world_readable_folder,
)

from autograder.sandbox.sweep import STUDENT_UID_BASE, user_ipc, user_processes

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(os.geteuid() != 0 or not shutil.which("setpriv")
                       or not shutil.which("unshare"),
                       reason="needs root, setpriv and unshare to make the shapes"),
]

REPO = Path(__file__).resolve().parents[2]
MINI = REPO / "tests" / "fixtures" / "mini_course"
CORPUS = REPO / "tests" / "submissions" / "hostile"
NAMES = sorted(p.name for p in CORPUS.iterdir())
AUTOGRADER = Path(sys.executable).with_name("autograder")
# What acts on every process and domain of the grader's user (stopping, tracing, joining,
# hoarding): alone where that user is the student's too.
ALONE_IN_BASIC = ("holds_every_domain", "joins_other_domain", "snoops_processes",
                  "stops_the_grader")
# What a shape changes about a grading: who the student is (a user of its own, or the
# grader's: root without CAP_SETUID, or an ordinary user), what bounds it (no writable
# cgroup in any of the three: rlimits and its user) and how what it leaves is ended (by its
# user, or by its process group and the shape's PID namespace). These programs' outcome
# rests on none of that: they end on their own (an exit, a signal, an import that never
# ends in a node), or write output or messages that one reader handles the same in every
# shape, or act on the graph and the network, which the three shapes share alike (no
# network namespace; the network test's host does not exist here). Strict isolation and
# the container grade them; the basic shapes, whose grader runs the same code as each
# other, grade every other program.
SAME_IN_EVERY_SHAPE = ("fake_score", "import_loop", "os_exit", "segfault",
                       "sys_exit_before_spin", "output_flood", "flood_before_node",
                       "fakes_clock_briefly", "network", "topic_flood")


@dataclasses.dataclass(frozen=True)
class Shape:
    name: str
    prefix: tuple[str, ...]
    mode: str  # the isolation the grader must choose there
    official: bool


SHAPES = (
    Shape("container", tuple(container(DOCKER_CAPS)), "user", True),
    Shape("basic-as-root", tuple(container(NO_SETUID_CAPS, own_pids=True)), "basic", False),
    Shape("ordinary-user", tuple(ordinary_user()), "basic", False),
)


@dataclasses.dataclass(frozen=True)
class Graded:
    """One program's grading in a shape: its results file and the programs' output."""

    results: dict
    log: str
    folder: Path  # where the batch ran (submissions/, out/)

    @property
    def messages(self) -> str:
        return "\n".join(t.get("output", "") + t.get("message", "")
                         for t in self.results.get("tests", []))


def _batch(shape: Shape, work: Path, names: list[str], jobs: int) -> None:
    submissions = work / f"submissions-{names[0]}"
    for name in names:
        shutil.copytree(CORPUS / name, submissions / name)
    for path in [submissions, *submissions.rglob("*")]:
        path.chmod(0o755 if path.is_dir() else 0o644)
    env = {**clean_env(os.environ.get("PATH", "")), "HOME": str(work),
           "AUTOGRADER_COURSE": str(work / "course"), "XDG_CACHE_HOME": str(work / "cache")}
    command = [*shape.prefix, str(AUTOGRADER), "grade-batch", "shout", str(submissions),
               "--csv", str(work / "out" / f"gradebook-{names[0]}.csv"), "--out", str(work / "out"),
               "--jobs", str(jobs), *([] if shape.official else ["--allow-unofficial"])]
    done = subprocess.run(command, env=env, cwd=work, capture_output=True, text=True,
                          timeout=1500)
    # exit 3 is a grader fault in some grading: the tests below say which, and why
    assert done.returncode in (0, 3), done.stdout[-3000:] + done.stderr[-3000:]


def programs(shape: Shape) -> list[str]:
    """The corpus's programs graded in ``shape``: all in the container, where the student
    is a user of its own; in a basic shape, those whose outcome it can change."""
    if shape.mode == "basic":
        return [name for name in NAMES if name not in SAME_IN_EVERY_SHAPE]
    return NAMES


@pytest.fixture(scope="module", params=SHAPES, ids=lambda shape: shape.name)
def shape_run(request: pytest.FixtureRequest) -> Iterator[tuple[Shape, dict[str, Graded]]]:
    """The corpus graded in one shape: each program's results and output."""
    shape: Shape = request.param
    work = world_readable_folder("autograder-shape-")
    work.chmod(0o777)  # the ordinary user writes its reports here
    try:
        shutil.copytree(MINI, work / "course")
        for path in [work / "course", *(work / "course").rglob("*")]:
            path.chmod(0o755 if path.is_dir() else 0o644)
        names = programs(shape)
        if shape.mode == "basic":
            _batch(shape, work, [n for n in names if n not in ALONE_IN_BASIC], jobs=2)
            for name in ALONE_IN_BASIC:  # each in a batch (and PID namespace) of its own:
                _batch(shape, work, [name], jobs=1)  # what it leaves ends with that batch
        else:
            _batch(shape, work, names, jobs=2)
        graded = {}
        for name in names:
            folder = work / "out" / name
            results = json.loads((folder / "results.json").read_text())
            log = folder / "output.log"
            graded[name] = Graded(results, log.read_text(errors="replace")
                                  if log.exists() else "", work)
        yield shape, graded
    finally:
        if shape.name == "ordinary-user":
            subprocess.run(["pkill", "-KILL", "-u", str(NOBODY)], check=False)
        shutil.rmtree(work, ignore_errors=True)


def _in(shape_run: tuple[Shape, dict[str, Graded]], *names: str) -> None:
    if shape_run[0].name not in names:
        pytest.skip(f"the table claims nothing for {shape_run[0].name} here")


# What basic isolation cannot keep from the grader's own user: the grading is the
# grader's failure, never a verdict.
EXPECTED_FAULTS = {("basic-as-root", "stops_the_grader"), ("ordinary-user", "stops_the_grader")}
# A program that traces every process it may (the simulator's too, as the grader's user)
# stops what it attaches to: never a verdict it earned, at worst the grader's failure.
MAY_FAULT = {("basic-as-root", "snoops_processes"), ("ordinary-user", "snoops_processes")}


@pytest.mark.parametrize("name", NAMES)
def test_ends_with_a_score_a_message_and_the_shapes_label(shape_run, name):
    shape, graded = shape_run
    if name not in programs(shape):
        pytest.skip(f"{name}'s outcome is the same in every shape (SAME_IN_EVERY_SHAPE): "
                    "graded in strict isolation and the container")
    results = graded[name].results
    isolation = results["isolation"]
    assert isolation["mode"] == shape.mode, isolation
    assert isolation["official"] is shape.official
    assert results["max_score"] == 3 and 0 <= results["score"] <= 3
    if (shape.name, name) in EXPECTED_FAULTS:
        assert results["grader_error"], "a stopped grading gave a verdict"
        return
    if (shape.name, name) in MAY_FAULT:
        return  # a grader fault or a verdict: it may have stopped the world it ran beside
    assert results["grader_error"] is None, results.get("grader_details", "")[-2000:]
    for test in results["tests"]:
        assert test["status"] == "passed" or test["message"].strip(), test


def _left_running(graded: dict[str, Graded]) -> list[int]:
    uids = {uid for g in graded.values() for uid in g.results["isolation"]["student_uids"]
            or []}
    return [pid for uid in sorted(uids) for pid in user_processes(uid)]


def test_each_student_has_a_user_of_its_own_and_nothing_is_left(shape_run):
    _in(shape_run, "container")
    _shape, graded = shape_run
    for name, g in graded.items():
        uids = g.results["isolation"]["student_uids"]
        assert uids and all(uid >= STUDENT_UID_BASE for uid in uids), name
    assert _left_running(graded) == []
    for g in graded.values():
        for uid in g.results["isolation"]["student_uids"]:
            assert user_ipc(uid) == []


def _read_nothing_of_the_course(shape_run: tuple[Shape, dict[str, Graded]], submission: str,
                                tried: str, read: str) -> None:
    """In the container shape, ``submission`` ran to the end (it says ``tried``) and not one
    line it printed as read (``read``, then the path) names a file of the course."""
    _in(shape_run, "container")
    g = shape_run[1][submission]
    assert g.results["score"] == 3 and tried in g.log
    assert not [line for line in g.log.splitlines()
                if line.startswith(read) and str(g.folder) in line]


def test_hidden_tests_and_solutions_stay_closed(shape_run):
    _read_nothing_of_the_course(shape_run, "reads_secrets", "SECRETS FOUND", "SECRET ")


def test_classmates_files_stay_closed(shape_run):
    _read_nothing_of_the_course(shape_run, "reads_classmates", "CLASSMATES READ:", "CLASSMATE ")


def test_no_result_is_rewritten(shape_run):
    _in(shape_run, "container")
    g = shape_run[1]["rewrites_results"]
    assert g.results["score"] == 3 and "REWROTE" not in g.log
    for other in shape_run[1].values():
        assert "FORGED" not in json.dumps(other.results)


def test_modules_beside_the_node_never_run_by_the_grader(shape_run):
    g = shape_run[1]["shadows_stdlib"]
    assert "ROOT CODE RAN" not in g.log
    importers = {int(uid) for uid in re.findall(r"^SHADOW \w+ IMPORTED AS UID (\d+)$",
                                                g.log, re.M)}
    if shape_run[0].name == "container":
        assert importers <= set(g.results["isolation"]["student_uids"])


def test_the_graders_processes_cannot_be_stopped_or_traced(shape_run):
    _in(shape_run, "container")
    g = shape_run[1]["snoops_processes"]
    assert g.results["score"] == 3
    assert re.search(r"^PROCESSES SEEN \d+ FOREIGN \d+ STOPPED 0$", g.log, re.M), g.log[-2000:]
    assert "TRACED 0" in g.log and "NoNewPrivs:\t1" in g.log
    stopper = shape_run[1]["stops_the_grader"]
    assert stopper.results["score"] == 3 and "MEM OPENED" not in stopper.log


def test_a_stopped_grading_is_the_graders_failure_and_its_memory_closed(shape_run):
    """The grading's pytest process and the grader itself are not dumpable: neither is
    read nor traced (a trace would stop it) by a program of the same user; a stopped
    pytest process makes the grading the grader's failure."""
    _in(shape_run, "basic-as-root", "ordinary-user")
    g = shape_run[1]["stops_the_grader"]
    assert g.results["grader_error"] and g.results["isolation"]["official"] is False
    assert "MEM OPENED" not in g.log
    assert "NoNewPrivs" in shape_run[1]["snoops_processes"].log  # it ran, traced, and the
    # batch that graded it went on to the end (a traced grader would have stopped there)


def test_tampering_with_the_world_is_caught(shape_run):
    for name in ("publishes_world_topics", "probe_name"):
        g = shape_run[1][name]
        assert g.results["score"] < 3
        assert "Tampering with the simulated world" in g.messages, name
    params = shape_run[1]["sets_grader_params"]
    assert params.results["score"] == 3 and "PARAMS: changed" not in params.log


def test_joining_another_domain_fails_only_the_joiner(shape_run):
    """Two at a time: a classmate graded beside the joiner is disturbed at most, then
    graded again (every other program's grading above has no grader fault)."""
    _in(shape_run, "container")
    g = shape_run[1]["joins_other_domain"]
    assert g.results["grader_error"] is None
    if "JOINED DOMAIN" in g.log:
        assert g.results["score"] < 3 and "which is not its own" in g.messages


def test_hoarding_every_domain_blocks_no_classmate(shape_run):
    _in(shape_run, "container")
    g = shape_run[1]["holds_every_domain"]
    assert re.search(r"^HOARDING \d+ LOCKS", g.log, re.M)
    assert g.results["grader_error"] is None  # and every other grading got its domain


def test_scratch_files_are_swept(shape_run):
    _in(shape_run, "container")
    g = shape_run[1]["ipc_leftovers"]
    names = re.findall(r"^FILE LEFT (\S+)", g.log, re.M)
    assert not [name for name in names if Path(name).exists()]
    for uid in g.results["isolation"]["student_uids"]:
        assert user_ipc(uid) == []


STALL = REPO / "tests" / "submissions" / "stalls" / "starves_the_world"


@pytest.mark.parametrize("prefix", [(), SHAPES[0].prefix, SHAPES[2].prefix],
                         ids=["strict", "container", "ordinary-user"])
def test_children_that_starve_the_world_fail_the_program_not_the_machine(prefix):
    """A silent node whose 100 spinning children starve the world (without a cgroup, in
    the container, every wait stalls): the program's zero, never "the machine was too
    busy" (a grader error, graded again). Graded alone: beside it a classmate's stalled
    grading would rightly be the machine's failure."""
    work = world_readable_folder("autograder-stall-")
    try:
        shutil.copytree(MINI, work / "course")
        shutil.copytree(STALL, work / "submission")
        for path in [work, *work.rglob("*")]:
            path.chmod(0o777 if path.is_dir() else 0o644)
        env = {**clean_env(os.environ.get("PATH", "")), "HOME": str(work),
               "AUTOGRADER_COURSE": str(work / "course")}
        done = subprocess.run([*prefix, str(AUTOGRADER), "grade", "shout",
                               str(work / "submission"), "--results",
                               str(work / "results.json")],
                              env=env, cwd=work, capture_output=True, text=True, timeout=600)
        results = json.loads((work / "results.json").read_text())
        assert results["grader_error"] is None, done.stdout[-3000:] + done.stderr[-3000:]
        assert done.returncode == 0
        assert results["score"] <= 1  # the node starts; it never answers
        messages = [t.get("message") or "" for t in results["tests"]]
        stalled = [m for m in messages if "the node kept the machine too busy" in m]
        # In the container (no cgroup) they stall every wait; each stall, wherever one
        # comes, says how far the world got. (As an ordinary user they did not: its tests
        # failed as a silent node's do, "no answer on shout".)
        assert stalled or prefix != SHAPES[0].prefix, messages
        assert all("the simulation advanced" in message for message in stalled)
    finally:
        shutil.rmtree(work, ignore_errors=True)
