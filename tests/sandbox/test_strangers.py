"""Other users cannot spoil a grading, and a student cannot spoil another's (issue 29).

Where runs share the machine's network (isolation by user: Gradescope's container, a pod
grading several students at once), a program can join another grading's ROS domain. The
grader tells who is on its domain from the sockets bound to the domain's Fast DDS ports,
each kept with the user who made it: a stranger's disturbs the grading (the grader's
failure, never the student's zero); the student's own on another domain's ports fails its
own grading."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import pytest
from conftest import modes_kept

from autograder.core.exercise import find_exercise
from autograder.grading.run import grade
from autograder.sandbox.domains import hold_domain

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(os.geteuid() != 0 or not shutil.which("setpriv"),
                       reason="needs root and setpriv to run programs as other users"),
]

COURSE = Path(__file__).parents[1] / "fixtures" / "mini_course"
CORPUS = Path(__file__).parents[1] / "submissions" / "hostile"
NOBODY = 65534


@pytest.fixture
def shout(monkeypatch: pytest.MonkeyPatch):
    """The mini course's exercise, graded in isolation by user (root, no namespaces)."""
    monkeypatch.setenv("AUTOGRADER_COURSE", str(COURSE))
    monkeypatch.setenv("AUTOGRADER_ISOLATION", "user")
    from autograder.sandbox import isolation

    isolation.forget()
    with modes_kept(isolation.protected_paths(COURSE)):
        yield find_exercise("shout")
    isolation.forget()


def _participant(domain: int, code: str, uid: int | None = None,
                 env: dict[str, str] | None = None) -> subprocess.Popen:
    """A program with an rclpy participant on ``domain`` (as ``uid``, if given)."""
    env = {"PATH": os.environ.get("PATH", ""), "ROS_DOMAIN_ID": str(domain),
           "HOME": "/tmp", "ROS_LOG_DIR": "/tmp", "PYTHONUNBUFFERED": "1", **(env or {})}
    command = [sys.executable, "-I", "-c", textwrap.dedent(code)]
    if uid is not None:
        command = ["setpriv", f"--reuid={uid}", f"--regid={uid}", "--clear-groups", *command]
    return subprocess.Popen(command, env=env, cwd="/", stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)


def _stop(process: subprocess.Popen) -> str:
    process.kill()
    output, _ = process.communicate(timeout=30)
    return output


IDLE = """
    import rclpy, time
    rclpy.init()
    node = rclpy.create_node("another_grading")
    print("UP", flush=True)
    time.sleep(600)
"""

# Joins every domain whose ports appear on the machine after it started, and publishes
# junk there on the exercise's output topic.
SPOILER = """
    import time, rclpy
    from rclpy.context import Context
    from std_msgs.msg import String

    def domains():
        found = set()
        for table in ("/proc/net/udp", "/proc/net/udp6"):
            for line in open(table).read().splitlines()[1:]:
                port = int(line.split()[1].rsplit(":", 1)[1], 16)
                if port >= 7400 and (port - 7400) // 250 <= 232:
                    found.add((port - 7400) // 250)
        return found

    before, joined = domains(), {}
    print("WATCHING", flush=True)
    end = time.monotonic() + 300
    while time.monotonic() < end:
        for domain in domains() - before - set(joined):
            context = Context()
            rclpy.init(context=context, domain_id=domain)
            node = rclpy.create_node("spoiler", context=context)
            joined[domain] = node.create_publisher(String, "shout", 10)
            print("JOINED", domain, flush=True)
        for publisher in joined.values():
            publisher.publish(String(data="SPOILED"))
        time.sleep(0.02)
"""


def _wait_for(process: subprocess.Popen, line: str) -> None:
    assert process.stdout is not None
    for got in process.stdout:  # ends at the program's end: a deadline of its own
        if got.strip() == line:
            return
    raise AssertionError(f"the helper program ended before saying {line}")


def test_a_student_who_joins_another_grading_fails_its_own(shout):
    """Another grading runs on a domain of its own; the student's program joins it."""
    with hold_domain() as other:
        victim = _participant(other.domain, IDLE)
        try:
            _wait_for(victim, "UP")
            result = grade(shout, CORPUS / "joins_other_domain")
        finally:
            _stop(victim)
    assert result.isolation.mode == "user"
    assert f"JOINED DOMAIN {other.domain}" in result.log
    assert result.grader_error is None, result.grader_details
    assert result.score < result.max_score
    messages = "\n".join(t.message for t in result.tests)
    assert f"your program joined ROS domain {other.domain}, which is not its own" in messages


def test_a_stranger_on_the_domain_disturbs_the_grading_and_blames_nobody(shout, monkeypatch):
    """A program of another user joins the grading's domain and publishes junk on the
    topic the tests read: the grading is the grader's failure, named as a disturbance,
    and no test says the student tampered with anything. (This stranger stays until the
    test ends, so the grading is not done again here: the test after this one does.)"""
    monkeypatch.setattr("autograder.grading.run.REGRADES", 0)
    spoiler = _participant(0, SPOILER, uid=NOBODY)
    try:
        _wait_for(spoiler, "WATCHING")
        result = grade(shout, COURSE / "assignments" / "shout" / "solution")
    finally:
        output = _stop(spoiler)
    assert "JOINED" in output, output[-2000:]
    assert result.grader_error is not None
    assert f"a program of another user (uid {NOBODY}) joined this grading's ROS domain" \
        in result.grader_details
    assert "Tampering" not in "\n".join(t.message for t in result.tests)


SUBSCRIBER = """
    import os, socket, struct, time, rclpy
    from std_msgs.msg import String
    rclpy.init()
    node = rclpy.create_node("student_side")
    got = []
    node.create_subscription(String, "loopback", lambda m: got.append(m.data), 10)
    end = time.monotonic() + 30
    while time.monotonic() < end and not got:
        rclpy.spin_once(node, timeout_sec=0.1)
    print("GOT" if got else "NOTHING", flush=True)
    mine = set()  # this process's sockets, by inode
    for fd in os.listdir("/proc/self/fd"):
        try:
            target = os.readlink(f"/proc/self/fd/{fd}")
        except OSError:
            continue
        if target.startswith("socket:["):
            mine.add(target[8:-1])
    for table in ("/proc/net/udp", "/proc/net/udp6"):
        for line in open(table).read().splitlines()[1:]:
            fields = line.split()
            if fields[9] in mine:
                address = fields[1].rsplit(":", 1)[0]
                if len(address) == 8:
                    address = socket.inet_ntoa(struct.pack("<I", int(address, 16)))
                print("BOUND", address, flush=True)
"""

PUBLISHER = """
    import time, rclpy
    from std_msgs.msg import String
    rclpy.init()
    node = rclpy.create_node("grader_side")
    publisher = node.create_publisher(String, "loopback", 10)
    print("UP", flush=True)
    while True:
        publisher.publish(String(data="hello"))
        rclpy.spin_once(node, timeout_sec=0.05)
"""


def test_the_loopback_profile_talks_across_users_and_binds_nothing_else():
    """Isolation by user's Fast DDS profile: root's participant and another user's talk,
    and every socket the other user's participant binds is on 127.0.0.1 (or the
    discovery multicast group, joined on loopback): no other interface is listened on."""
    from autograder.sandbox.isolation import LOOPBACK_PROFILE, PROFILE_ENV

    folder = Path(tempfile.mkdtemp(prefix="autograder-profile-"))  # readable by the user
    folder.chmod(0o755)
    profile = folder / "profile.xml"
    profile.write_bytes(LOOPBACK_PROFILE.read_bytes())
    profile.chmod(0o644)
    extra = {PROFILE_ENV: str(profile)}
    try:
        with hold_domain() as lock:
            grader = _participant(lock.domain, PUBLISHER, env=extra)
            try:
                _wait_for(grader, "UP")
                student = _participant(lock.domain, SUBSCRIBER, uid=NOBODY, env=extra)
                output, _ = student.communicate(timeout=120)
            finally:
                _stop(grader)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    assert "GOT" in output.splitlines(), output
    bound = [line.split()[1] for line in output.splitlines() if line.startswith("BOUND ")]
    assert bound, output
    for address in bound:
        assert address == "127.0.0.1" or 224 <= int(address.split(".")[0]) <= 239, bound


def test_a_program_that_hoards_every_domain_blocks_no_classmate(shout):
    """A student's program locks every shared domain lock and binds every grading
    domain's first port, and keeps a daemon holding them. A classmate's grading started
    meanwhile still gets a domain; where the hoarder's socket sat on its domain it is
    graded again once the hoarder is gone, and keeps its full marks. The hoarder's own
    grading fails for joining domains not its own."""
    from concurrent.futures import ThreadPoolExecutor

    marker = Path("/tmp")  # where the hoarder says it holds them
    before = set(marker.glob("hoarding-*"))
    with ThreadPoolExecutor(max_workers=1) as pool:
        hoarding = pool.submit(grade, shout, CORPUS / "holds_every_domain")
        deadline = time.monotonic() + shout.time_limit
        while not set(marker.glob("hoarding-*")) - before and not hoarding.done():
            assert time.monotonic() < deadline, "the hoarder never started"
            time.sleep(0.05)
        overlapping = not hoarding.done()
        classmate = grade(shout, COURSE / "assignments" / "shout" / "solution")
        hoarder = hoarding.result()
    assert overlapping, "the hoarder's grading ended before the classmate's began"
    held = re.findall(r"^HOARDING (\d+) LOCKS (\d+) PORTS AS UID (\d+)$", hoarder.log, re.M)
    assert sum(int(locks) for locks, _ports, _uid in held) > 0, hoarder.log[-2000:]
    assert classmate.grader_error is None, classmate.grader_details
    assert classmate.score == classmate.max_score
    for strangers in classmate.disturbed:
        assert set(strangers) <= {int(uid) for _locks, _ports, uid in held}
    assert hoarder.grader_error is None and hoarder.score < hoarder.max_score
    assert "which is not its own" in "\n".join(t.message for t in hoarder.tests)


def test_a_disturbed_grading_is_graded_again_once_the_stranger_is_gone(shout):
    """A socket of another grading's student sits on this grading's domain for a few
    seconds: the tests it overlapped prove nothing, so the whole grading is done again
    once that user has nothing left on the machine, and its full marks stand."""
    from autograder.sandbox.domains import DOMAIN_GAIN, PORT_BASE
    from autograder.sandbox.sweep import STUDENT_UID_BASE

    stranger = STUDENT_UID_BASE + 230  # a domain no grading here uses
    with hold_domain() as free:
        domain = free.domain
    code = (f"import socket, sys\ns = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)\n"
            f"s.bind(('127.0.0.1', {PORT_BASE + DOMAIN_GAIN * domain}))\n"
            f"print('BOUND', flush=True)\nsys.stdin.read()\n")
    sitter = subprocess.Popen(["setpriv", f"--reuid={stranger}", f"--regid={stranger}",
                               "--clear-groups", sys.executable, "-I", "-c", code],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                              cwd="/")
    assert sitter.stdout is not None and sitter.stdin is not None
    _wait_for(sitter, "BOUND")

    def leave_once_seen(test) -> None:  # the first test's end: it overlapped the sitter
        if not sitter.stdin.closed:
            sitter.stdin.close()

    try:
        result = grade(shout, COURSE / "assignments" / "shout" / "solution", domain=domain,
                       progress=leave_once_seen)
    finally:
        if not sitter.stdin.closed:
            sitter.stdin.close()
        sitter.wait(timeout=30)
    assert result.disturbed == ((stranger,),)
    assert result.grader_error is None, result.grader_details
    assert result.score == result.max_score
