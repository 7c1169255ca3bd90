"""Hostile and broken submissions: each ends with a score, a plain message and a results
file, leaves no process behind, and leaves the grader unharmed and on time.

The corpus (tests/submissions/hostile/) targets the small `shout` exercise of the fixture
course, so the whole corpus grades in about a minute."""

from __future__ import annotations

import contextlib
import json
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from markupsafe import escape

from autograder.commands.grade import write_outputs
from autograder.core.exercise import find_exercise
from autograder.core.results import RunResult
from autograder.grading.run import grade
from autograder.render.terminal import to_terminal
from autograder.sandbox.isolation import detect
from autograder.sandbox.leftovers import leftovers
from autograder.sandbox.process import STRICT_WORKDIR_PREFIX

pytestmark = pytest.mark.slow

COURSE = Path(__file__).parents[1] / "fixtures" / "mini_course"
CORPUS = Path(__file__).parents[1] / "submissions" / "hostile"
NAMES = sorted(p.name for p in CORPUS.iterdir())
TARGET = ("10.231.77.2", 8765)  # the network test's own host, in a namespace it makes


@pytest.fixture(scope="module")
def course():
    old = os.environ.get("AUTOGRADER_COURSE")
    os.environ["AUTOGRADER_COURSE"] = str(COURSE)
    yield find_exercise("shout")
    if old is None:
        del os.environ["AUTOGRADER_COURSE"]
    else:
        os.environ["AUTOGRADER_COURSE"] = old


def _remove_stale_targets(ip: Callable[..., None]) -> None:
    """A run killed before its teardown leaves its namespace and its veth holding the
    target's addresses, and the next run's target is then unreachable: remove those whose
    test process is gone."""
    listing = subprocess.run(["ip", "netns", "list"], capture_output=True, text=True).stdout
    for name in re.findall(r"^agtarget(\d+)", listing, re.M):
        if not Path(f"/proc/{name}").exists():
            with contextlib.suppress(subprocess.CalledProcessError):
                ip("link", "del", f"agh{name}")
            with contextlib.suppress(subprocess.CalledProcessError):
                ip("netns", "del", f"agtarget{name}")


@pytest.fixture(scope="module")
def target_host():
    """A TCP server in a network namespace of this test's own, reachable from the host."""
    if os.geteuid() != 0 or shutil.which("ip") is None:
        yield None
        return
    ns, host_if, peer_if = f"agtarget{os.getpid()}", f"agh{os.getpid()}", f"agt{os.getpid()}"
    received = Path(f"/tmp/{ns}.received")

    def ip(*args: str) -> None:
        subprocess.run(["ip", *args], check=True, capture_output=True)

    server = None
    _remove_stale_targets(ip)
    try:
        ip("netns", "add", ns)
        ip("link", "add", host_if, "type", "veth", "peer", "name", peer_if)
        ip("link", "set", peer_if, "netns", ns)
        ip("addr", "add", "10.231.77.1/24", "dev", host_if)
        ip("link", "set", host_if, "up")
        ip("netns", "exec", ns, "ip", "addr", "add", "10.231.77.2/24", "dev", peer_if)
        ip("netns", "exec", ns, "ip", "link", "set", peer_if, "up")
        ip("netns", "exec", ns, "ip", "link", "set", "lo", "up")
        code = (f"import socket\ns = socket.create_server(('0.0.0.0', {TARGET[1]}))\n"
                f"while True:\n    c, _ = s.accept()\n"
                f"    open({str(received)!r}, 'ab').write(c.recv(100) or b'(connected)')\n"
                f"    c.close()\n")
        server = subprocess.Popen(["ip", "netns", "exec", ns, sys.executable, "-c", code])
        deadline = time.monotonic() + 10
        while True:  # the target is reachable from outside the sandbox: the test can fail
            try:
                socket.create_connection(TARGET, timeout=1).close()
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.1)
        received.write_bytes(b"")
        yield received
    finally:
        if server is not None:
            server.kill()
            server.wait()
        subprocess.run(["ip", "netns", "del", ns], capture_output=True)
        subprocess.run(["ip", "link", "del", host_if], capture_output=True)
        received.unlink(missing_ok=True)


def student_folders() -> set[Path]:
    """The folders of students' programs in strict isolation, in the temporary folder."""
    return set(Path(tempfile.gettempdir()).glob(f"{STRICT_WORKDIR_PREFIX}*"))


@pytest.fixture(scope="module")
def corpus_run(course, target_host) -> tuple[dict[str, tuple[RunResult, float, list[int]]],
                                             list[Path]]:
    """Every submission of the corpus graded (two at a time), and the folders of
    students' programs that the gradings left in the temporary folder."""
    def run(name: str) -> tuple[str, tuple[RunResult, float, list[int]]]:
        began = time.monotonic()
        result = grade(course, CORPUS / name)
        return name, (result, time.monotonic() - began, leftovers(result))

    before = student_folders()
    with ThreadPoolExecutor(max_workers=2) as pool:
        graded = dict(pool.map(run, NAMES))
    return graded, sorted(student_folders() - before)


@pytest.fixture(scope="module")
def graded(corpus_run) -> dict[str, tuple[RunResult, float, list[int]]]:
    return corpus_run[0]


def test_no_folder_is_left_behind(corpus_run):
    """Nor a folder: a program's own (strict isolation) goes when it is stopped."""
    assert corpus_run[1] == []


def messages(result: RunResult) -> str:
    return "\n".join(t.message for t in result.tests)


@pytest.mark.parametrize("name", NAMES)
def test_ends_with_a_score_a_message_and_nothing_left(graded, course, name):
    result, wall, left = graded[name]
    assert result.grader_error is None, result.grader_details
    assert left == [], f"processes left behind: {left}"
    assert wall < course.time_limit
    data = json.loads(json.dumps(result.to_dict()))
    assert data["max_score"] == 3 and 0 <= data["score"] <= 3
    for test in result.tests:
        assert test.passed or test.message.strip(), test


@pytest.mark.parametrize("name", ["import_loop", "sleep_forever", "fork_bomb", "memory_bomb",
                                  "output_flood", "huge_file", "os_exit", "segfault",
                                  "sys_exit_before_spin", "flood_before_node"])
def test_programs_that_never_run_a_node_score_zero(graded, name):
    assert graded[name][0].score == 0


@pytest.mark.parametrize("name,expected", [
    ("segfault", "SIGSEGV"), ("memory_bomb", "MemoryError"), ("huge_file", "File too large"),
    ("output_flood", "bytes of output; only the first and last"),
    ("flood_before_node", "bytes of output; only the first and last"),
    ("flood_before_node", "RuntimeError: gave up after the flood"),
    ("os_exit", "exited with status 0"),
    ("sys_exit_before_spin", "exited with status 0"),
    ("import_loop", "No node named 'shouter'"),
])
def test_the_message_says_what_happened(graded, name, expected):
    assert expected in messages(graded[name][0])


def test_a_thread_left_in_the_kernel_holds_sim_time_once(graded):
    """A node with a thread in uninterruptible sleep (state D) for good is waited for from
    its store (``blocked_reserve``) once, not every tick: each module's holds drew on it,
    none ran to ``hold_cap``, and the node, which works, keeps its score."""
    result = graded["blocks_in_the_kernel"][0]
    assert result.score == 3, messages(result)
    assert result.pacing
    for module, pacing in result.pacing.items():
        assert pacing.blocked_waits and pacing.count("cap") == 0, (module, pacing)


@pytest.mark.parametrize("name", ["publishes_world_topics", "probe_name"])
def test_tampering_is_caught_not_rewarded(graded, name):
    result = graded[name][0]
    assert result.score < result.max_score
    assert "Tampering with the simulated world" in messages(result)


MB = 1 << 20


@pytest.mark.parametrize("name", ["flood_before_node", "output_flood"])
def test_output_floods_stay_out_of_the_messages(graded, name):
    """Each message carries a few lines of the output, whatever the program wrote."""
    for test in graded[name][0].tests:
        assert len(test.message.encode()) <= 4096, test.name
        assert len(test.message.splitlines()) <= 20, test.name


def test_a_flood_gives_small_results_and_its_whole_log_once(graded, course, tmp_path):
    """64 MB before the node: results files well under 1 MB; the kept output, head and
    tail, once in the HTML report and in the log file beside the results."""
    result = graded["flood_before_node"][0]
    files = {name: tmp_path / f"out.{name}" for name in ("results", "html", "gradescope",
                                                          "junit")}
    write_outputs(result, dict(files), course.folder)
    for name in ("results", "gradescope", "junit"):
        assert files[name].stat().st_size < MB, name
    assert len(to_terminal(result).encode()) < MB
    log = (tmp_path / "out.log").read_text(encoding="utf-8")
    assert log == result.log
    assert "FLOOD BEGINS" in log and "RuntimeError: gave up after the flood" in log
    assert "bytes of output dropped" in log  # the sandbox's budget, not ours, cut it
    assert len(log) > 256 * 1024 > 16 * files["results"].stat().st_size  # not in the JSON
    html = files["html"].read_text(encoding="utf-8")
    assert html.count(str(escape(log))) == 1


def test_a_flood_does_not_stop_grading(graded):
    result, wall, _ = graded["topic_flood"]
    assert result.grader_error is None and result.score < result.max_score


strict_only = pytest.mark.skipif(not detect().strict, reason=f"needs strict isolation: "
                                 f"{detect().reason}")


@strict_only
def test_hidden_tests_and_solutions_are_out_of_reach(graded):
    result = graded["reads_secrets"][0]
    assert "SECRETS FOUND: 0" in result.log_tail
    assert "SECRET /" not in result.log_tail


@strict_only
def test_results_and_grader_folders_cannot_be_written(graded):
    result = graded["writes_results"][0]
    assert "FORGED" not in result.log_tail and "PLANTED" not in result.log_tail
    assert result.score == result.max_score  # it works otherwise, and its forgery failed


@strict_only
def test_no_network_beyond_loopback(graded, target_host):
    if target_host is None:
        pytest.skip("needs root and iproute2 to build the target host")
    result = graded["network"][0]
    assert "NETWORK: blocked" in result.log_tail
    assert b"leaked" not in target_host.read_bytes()


def test_modules_beside_the_node_run_only_as_the_student(graded):
    """json.py, ctypes.py, sitecustomize.py... beside the node: imported by the student's
    own program at most, never by the launcher as root (issue 28)."""
    result = graded["shadows_stdlib"][0]
    assert result.score == result.max_score and result.grader_error is None
    assert "ROOT CODE RAN" not in result.log
    importers = re.findall(r"^SHADOW (\w+) IMPORTED AS UID (\d+)$", result.log, re.M)
    assert {name for name, _uid in importers} <= {"json"}  # the node's own imports only
    if result.isolation.mode == "strict":
        assert {int(uid) for _name, uid in importers} <= set(result.student_uids or ())


@strict_only
def test_ipc_objects_and_scratch_files_go_with_the_program(graded):
    """SysV shared memory, queues and semaphores, a POSIX queue and files in /dev/shm and
    /tmp: the program's own namespaces held them, and none is on the machine after."""
    result = graded["ipc_leftovers"][0]
    assert result.score == result.max_score, _lost(result)
    keys = {int(key, 16) for key in re.findall(r"^IPC SHM (0x[0-9a-f]+)", result.log, re.M)}
    assert keys, "the program made its segments"
    for kind in ("shm", "msg", "sem"):
        with open(f"/proc/sysvipc/{kind}") as fh:
            left = {int(row.split()[0]) for row in list(fh)[1:]}
        assert not left & keys, kind
    names = re.findall(r"^(?:FILE LEFT|IPC MQ) (\S+)", result.log, re.M)
    assert names
    for name in names:
        assert not Path(name).exists() and not Path("/dev/mqueue", name.lstrip("/")).exists()


def _lost(result: RunResult) -> str:
    """What each lost test said, and the grader's error: a failed check in CI says why."""
    return json.dumps({"grader_error": result.grader_error, "lost": {
        t.name: t.message for t in result.tests if t.status != "passed"}}, indent=1)


@strict_only
def test_no_other_grading_is_in_reach(graded):
    """Each grading has a network namespace of its own: no other domain's ports to join."""
    result = graded["joins_other_domain"][0]
    assert result.score == result.max_score and result.grader_error is None
    assert "JOINED DOMAIN" not in result.log


@strict_only
def test_classmates_are_out_of_reach(graded):
    """Other students' submissions and results anywhere on the machine (this checkout's
    corpus among them) are covered by the mount namespace."""
    result = graded["reads_classmates"][0]
    assert result.score == result.max_score
    assert "CLASSMATES READ: 0" in result.log and "CLASSMATE /" not in result.log


@strict_only
def test_the_machines_processes_are_out_of_sight_and_reach(graded):
    """No other user's process is listed, stopped or traced; no privilege can be gained."""
    result = graded["snoops_processes"][0]
    assert result.score == result.max_score
    assert "GRADER COMMAND LINE" not in result.log
    assert re.findall(r"^PROCESSES SEEN \d+ FOREIGN (\d+) STOPPED (\d+)$", result.log,
                      re.M) and "FOREIGN 0 STOPPED 0" in result.log
    assert "NoNewPrivs:\t1" in result.log
    assert "TRACED 0" in result.log


@strict_only
def test_without_cgroups_a_daemon_still_ends_with_the_program(course, monkeypatch):
    """Where no cgroup can be made (a container's read-only cgroup filesystem), what left
    the process group is ended by its user: nothing of the run's users is left."""
    monkeypatch.setenv("AUTOGRADER_CGROUP_ROOT", "/nonexistent")
    result = grade(course, CORPUS / "detached_daemon")
    assert result.grader_error is None
    assert result.isolation.bounds.cgroup is None  # it really had none
    assert re.search(r"^STUDENT UID \d+$", result.log, re.M), "the daemon started"
    assert leftovers(result) == []
    from autograder.sandbox.sweep import user_processes

    for uid in result.student_uids or ():
        assert user_processes(uid) == []


def test_runs_as_its_own_user_where_strict(graded):
    """The program (and the daemon it leaves behind) prints the uid it really runs as:
    the run's own user in strict isolation, never the grader's; the grader's user in basic
    isolation, and the results say why."""
    result = graded["detached_daemon"][0]
    isolation = result.isolation
    assert isolation.mode == detect().mode
    seen = {int(uid) for uid in re.findall(r"^STUDENT UID (\d+)$", result.log, re.M)}
    if isolation.mode == "strict":
        assert result.student_uid is not None
        # Test modules run in children of their own, each with its domain's user.
        assert seen and seen <= set(result.student_uids or ())
        assert os.getuid() not in seen
    else:
        assert result.student_uid is None
        assert seen == {os.getuid()}
        assert isolation.reason  # the results say why


def test_output_that_lies_shows_as_text(graded):
    """A program that clears the screen and prints a fake full score, sets the window's
    title, hides text, plants a link and reverses a line: every format shows all of it as
    text, and its NUL and BEL leave the JUnit XML well-formed."""
    import unicodedata
    import xml.etree.ElementTree as ET

    from autograder.render.gradescope import to_gradescope
    from autograder.render.jsonfile import to_json
    from autograder.render.junit import to_junit

    result = graded["fake_score"][0]
    assert result.score == result.max_score  # it works; only its output lies
    shown = {"terminal": to_terminal(result), "junit": to_junit(result),
             "gradescope": to_gradescope(result), "results": to_json(result),
             "log": result.log}
    for name, text in shown.items():
        assert not {c for c in text if unicodedata.category(c) in ("Cc", "Cf", "Cs")
                    and c not in "\n\t"}, name
    ET.fromstring(shown["junit"].encode("utf-8"))  # well-formed, as a CI reporter reads it
    for text in (result.log, shown["junit"]):  # the lie is there, to be read
        assert "\\x1b[2J\\x1b[H" in text and "\\x1b]0;autograder: all tests passed\\x07" in text
        assert "\\u202edessap stset lla\\u202c" in text and "NUL\\x00 BEL\\x07 CR" in text
    # The log tail (JUnit's system-out) is cut by lines, so there a lone CR ends a line.
    assert "CR\\r overwritten" in result.log and "C1 CSI \\x9b2J" in result.log


# Issue 28: the grader's nodes take no orders, and the graph is watched through each test.
def test_the_graders_nodes_serve_no_parameters(graded):
    """A program that tries to turn off use_sim_time on the world and the probe finds no
    service to call; it answers correctly otherwise, for full marks."""
    result = graded["sets_grader_params"][0]
    assert result.score == result.max_score
    for node in ("/sim_world", "/autograder_probe"):
        assert f"PARAMS: no service {node}/set_parameters" in result.log
    assert "PARAMS: changed" not in result.log and "PARAMS: refused" not in result.log


def test_a_clock_faked_for_a_moment_fails_the_tests_it_was_faked_in(graded):
    """/clock published for 0.3 s while a test waits for its answer fails that test (in
    each module, the one that sends the message); the test before it still passes."""
    result = graded["fakes_clock_briefly"][0]
    assert result.log.count("FAKE CLOCK: published for") == 2
    tests = {test.name: test for test in result.tests}
    assert tests["test_starts"].passed
    for name in ("test_upper_case", "test_once_per_message"):
        assert not tests[name].passed
        assert "Tampering with the simulated world" in tests[name].message, name
