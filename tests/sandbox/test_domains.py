"""ROS domains on a machine shared by users: locks any user may take, a clean fallback
where the shared folder cannot be used, and a domain in use on the wire is never taken."""

from __future__ import annotations

import fcntl
import os
import shutil
import socket
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest

from autograder.sandbox.domains import (
    DOMAIN_GAIN,
    FIRST_DOMAIN,
    PORT_BASE,
    NoDomain,
    busy_on_the_wire,
    hold_domain,
    reserve_domain,
)

REPO = Path(__file__).resolve().parents[2]
NOBODY = 65534
as_root = pytest.mark.skipif(os.geteuid() != 0 or not shutil.which("unshare")
                             or not shutil.which("setpriv"),
                             reason="needs root, unshare and setpriv to run as another user")

# Reserve a domain as another user and print it (or the error, with no traceback).
OTHER_USER = """
import sys
from autograder.sandbox.domains import NoDomain, hold_domain
try:
    with hold_domain() as lock:
        print("domain", lock.domain)
except NoDomain as exc:
    print("no domain", exc)
"""


@pytest.fixture
def lock_dir(monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A lock folder in a parent like /tmp: sticky, and every user may write there."""
    parent = Path(tempfile.mkdtemp(prefix="autograder-locks-", dir="/tmp"))
    os.chmod(parent, 0o1777)
    folder = parent / "domains"
    monkeypatch.setenv("AUTOGRADER_LOCK_DIR", str(folder))
    yield folder
    subprocess.run(["rm", "-rf", str(parent)], check=False)


def _as_nobody(lock_dir: Path) -> str:
    """Reserve a domain as another user, in a network namespace of its own: only the lock
    files decide then, not the ports that this busy machine's other runs hold."""
    env = dict(os.environ, AUTOGRADER_LOCK_DIR=str(lock_dir), PYTHONPATH=str(REPO))
    run = subprocess.run(["unshare", "--net", "setpriv", f"--reuid={NOBODY}",
                          f"--regid={NOBODY}", "--clear-groups", sys.executable, "-c",
                          OTHER_USER], capture_output=True, text=True, env=env, cwd="/",
                         timeout=60)
    assert run.returncode == 0 and "Traceback" not in run.stderr, run.stderr
    return run.stdout.strip()


@as_root
def test_another_user_locks_in_the_shared_folder_after_root(lock_dir):
    old = os.umask(0o077)  # the strictest umask: the files must still be lockable by all
    try:
        with hold_domain() as first:
            # The first domain whose lock root does not hold.
            other = FIRST_DOMAIN + 1 if first.domain == FIRST_DOMAIN else FIRST_DOMAIN
            assert _as_nobody(lock_dir) == f"domain {other}"
        assert oct(lock_dir.stat().st_mode & 0o7777) == "0o1777"
        assert oct((lock_dir / f"domain-{first.domain}.lock").stat().st_mode & 0o777) == "0o666"
        # Released: the other user may now lock root's file for every domain.
        assert _as_nobody(lock_dir) == f"domain {FIRST_DOMAIN}"
    finally:
        os.umask(old)


@as_root
def test_an_unusable_shared_folder_falls_back_to_the_users_own(lock_dir):
    # As an older version left it: a folder and a lock file only root may write, and a
    # run of root's holding the first domain.
    lock_dir.mkdir(mode=0o755)
    lock_dir.chmod(0o755)
    held = lock_dir / f"domain-{FIRST_DOMAIN}.lock"
    held.touch(mode=0o644)
    with held.open() as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        # The other user locks in a folder of its own, and still sees root's lock.
        assert _as_nobody(lock_dir) == f"domain {FIRST_DOMAIN + 1}"
    own = lock_dir.with_name(f"{lock_dir.name}-{NOBODY}")
    assert own.is_dir() and own.stat().st_uid == NOBODY


def test_a_domain_in_use_on_the_wire_is_skipped(lock_dir):
    with reserve_domain() as free:
        pass
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.bind(("127.0.0.1", PORT_BASE + DOMAIN_GAIN * free + 11))  # a DDS user port
        assert busy_on_the_wire(free)
        with reserve_domain() as domain:
            assert domain != free
        with pytest.raises(NoDomain, match="ports are in use"):
            with reserve_domain(free):
                pass
    assert not busy_on_the_wire(free)


# A student's program (a user of its own) locks every shared lock file and binds a socket
# on every grading domain's first port; half the locks it hands to a child and exits, so
# the kernel no longer names a live holder for them.
HOARDER = """
import fcntl, os, socket, sys, time
folder = sys.argv[1]
held, socks = [], []
for domain in range({first}, {last} + 1):
    path = f"{{folder}}/domain-{{domain}}.lock"
    try:
        fd = os.open(path, os.O_RDONLY | os.O_CREAT, 0o666)
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        held.append(fd)
    except OSError:
        pass
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        s.bind(("127.0.0.1", {base} + {gain} * domain))
        socks.append(s)
    except OSError:
        s.close()
if os.fork() == 0:  # the child keeps every lock; the locker itself is gone
    os.setsid()
    print("HELD", len(held), flush=True)
    sys.stdin.read()
    os._exit(0)
os._exit(0)
"""


def _hold_as(uid: int, code: str, *args: str) -> subprocess.Popen:
    """``code`` run as ``uid``; it says its first line once it holds what it holds, and
    lets go when its stdin closes."""
    return subprocess.Popen(["setpriv", f"--reuid={uid}", f"--regid={uid}", "--clear-groups",
                             sys.executable, "-I", "-c", code, *args],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, cwd="/")


def _let_go(process: subprocess.Popen) -> None:
    assert process.stdin is not None
    process.stdin.close()
    process.wait(timeout=30)


@as_root
def test_a_students_program_holding_every_lock_leaves_the_domains_free(lock_dir):
    """Issue 29: a program of a student's own user that locks every shared lock file
    (through a child, its locker gone) and binds every domain's port blocks nobody: root
    and an ordinary user both still get a domain."""
    from autograder.sandbox.domains import LAST_DOMAIN
    from autograder.sandbox.sweep import STUDENT_UID_BASE

    lock_dir.mkdir(mode=0o1777)
    lock_dir.chmod(0o1777)
    student = STUDENT_UID_BASE + 7
    hoarder = _hold_as(student, HOARDER.format(first=FIRST_DOMAIN, last=LAST_DOMAIN,
                                               base=PORT_BASE, gain=DOMAIN_GAIN), str(lock_dir))
    try:
        assert hoarder.stdout is not None
        said = hoarder.stdout.readline().split()  # ends with the child: a deadline of its own
        assert said and said[0] == "HELD" and int(said[1]) == LAST_DOMAIN - FIRST_DOMAIN + 1
        with hold_domain() as mine:
            assert FIRST_DOMAIN <= mine.domain <= LAST_DOMAIN
        assert _as_nobody(lock_dir).startswith("domain "), "the ordinary user got none"
    finally:
        _let_go(hoarder)
        subprocess.run(["pkill", "-KILL", "-u", str(student)], check=False)


@as_root
def test_a_lock_an_ordinary_users_run_holds_is_respected_by_root(lock_dir, monkeypatch):
    """Only students' users are passed over: a lock of another user's run keeps its
    domain from root. Only the lock files decide here: the test's lock folder is its own,
    so another run on this machine may take the same domain meanwhile and bind its ports
    (seen once in the fast tier: the domain, let go, was still refused)."""
    from autograder.sandbox import domains

    monkeypatch.setattr(domains, "busy_on_the_wire", lambda domain: False)
    lock_dir.mkdir(mode=0o1777)
    lock_dir.chmod(0o1777)
    with reserve_domain() as free:
        pass
    holder = _hold_as(NOBODY, "import fcntl, os, sys\n"
                      "fd = os.open(sys.argv[1], os.O_RDONLY | os.O_CREAT, 0o666)\n"
                      "fcntl.flock(fd, fcntl.LOCK_EX)\nprint('HELD', flush=True)\n"
                      "sys.stdin.read()\n", str(lock_dir / f"domain-{free}.lock"))
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "HELD"
        with pytest.raises(NoDomain), hold_domain(free):
            pass
    finally:
        _let_go(holder)
    with hold_domain(free) as lock:
        assert lock.domain == free


def test_the_shared_lock_folder_does_not_follow_tmpdir(monkeypatch, tmp_path):
    """Graders whose $TMPDIR differs (users, CI jobs, a test's own) lock in one folder: in
    strict isolation no bound port shows another run's domain, so a second folder would
    let two runs take the same domain and one's sweep of its student user end the other's."""
    from autograder.sandbox.domains import DEFAULT_LOCK_DIR, lock_dirs, shared_lock_dir

    monkeypatch.delenv("AUTOGRADER_LOCK_DIR", raising=False)
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    tempfile.tempdir = None  # read $TMPDIR again, as a process started with it would
    try:
        assert shared_lock_dir() == DEFAULT_LOCK_DIR == Path("/tmp/autograder-domains")
        assert not str(lock_dirs()[0]).startswith(str(tmp_path))
    finally:
        tempfile.tempdir = None
