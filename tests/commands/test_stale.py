"""Nodes a hand run left behind (issue 31): found by their folder, whose world's lock no
one holds, on the domain their environment names; the student's own stopped, with their
folders; and end to end, a hand run killed with SIGKILL leaves a node that the next hand
run on that domain stops and names."""

from __future__ import annotations

import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from autograder.commands import stale
from autograder.sandbox.domains import DOMAIN_GAIN, PORT_BASE, bound_on_domains

REPO = Path(__file__).resolve().parents[2]
NODES = REPO / "tests" / "fixtures" / "hand_node"
NOBODY = 65534
WALL = 120.0
# A program that stays until stopped: a stand-in for a node (nothing here waits on it).
IDLE = [sys.executable, "-c", "import signal; signal.pause()"]


@pytest.fixture()
def tmp() -> Iterator[Path]:
    """A temporary folder standing for the system's, where hand runs make theirs."""
    folder = Path(tempfile.mkdtemp(prefix="stale-"))
    folder.chmod(0o1777)
    try:
        yield folder
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def left_node(folder: Path, domain: int, user: int | None = None) -> subprocess.Popen[bytes]:
    """A program working in ``folder``'s student folder, on ``domain``, as a hand run
    starts the student's node (its own session)."""
    workdir = folder / "student-x"
    workdir.mkdir()
    if user is not None:
        for path in (folder, workdir):
            os.chown(path, user, user)
    prefix = [] if user is None else ["setpriv", f"--reuid={user}", f"--regid={user}",
                                      "--clear-groups"]
    node = subprocess.Popen([*prefix, *IDLE], cwd=workdir, start_new_session=True,
                            env={**os.environ, "ROS_DOMAIN_ID": str(domain)})
    deadline = time.monotonic() + 10
    while user is not None and Path(f"/proc/{node.pid}").stat().st_uid != user:
        assert time.monotonic() < deadline, "setpriv never became the user"
        time.sleep(0.01)  # until setpriv has changed user: a condition, with a deadline
    # Until the program runs: before its exec, /proc shows the parent's environment, which
    # holds no ROS_DOMAIN_ID of the node's (a loaded machine once found no node there).
    while IDLE[-1].encode() not in Path(f"/proc/{node.pid}/cmdline").read_bytes():
        assert time.monotonic() < deadline, "the node never started"
        time.sleep(0.01)
    return node


def test_a_node_in_a_folder_no_world_holds_is_stale_on_its_domain_only(tmp: Path) -> None:
    folder, lock = stale.hand_folder("velocity_governor.py", tmp)
    os.close(lock)  # its world is gone
    node = left_node(folder, 42)
    try:
        found = stale.find(42, tmp)
        assert [(n.pid, n.uid, n.folder, n.script) for n in found] == [
            (node.pid, os.getuid(), folder, "velocity_governor.py")]
        assert stale.find(43, tmp) == []
        stale.stop(found)
        assert node.wait(5) is not None
        assert not folder.exists()
    finally:
        node.kill()
        node.wait()


def test_a_node_whose_world_still_runs_is_not_stale(tmp: Path) -> None:
    folder, lock = stale.hand_folder("velocity_governor.py", tmp)
    node = left_node(folder, 42)
    try:
        assert stale.find(42, tmp) == []  # its world holds the lock: a live run
        os.close(lock)
        assert [n.pid for n in stale.find(42, tmp)] == [node.pid]
    finally:
        node.kill()
        node.wait()


def test_a_run_finds_what_works_in_its_own_folder_whatever_its_domain(tmp: Path) -> None:
    """Its backstop when it stops: a program forked while a signal cut its start short."""
    folder, lock = stale.hand_folder("velocity_governor.py", tmp)
    node = left_node(folder, 3)
    try:
        assert [n.pid for n in stale.working_in(folder)] == [node.pid]
        stale.stop(stale.working_in(folder))
        assert node.wait(5) is not None
    finally:
        os.close(lock)
        node.kill()
        node.wait()


def test_a_folder_an_older_version_left_counts_as_stale(tmp: Path) -> None:
    folder = Path(tempfile.mkdtemp(prefix=stale.HAND_PREFIX, dir=tmp))  # no lock file
    node = left_node(folder, 7)
    try:
        assert [n.pid for n in stale.find(7, tmp)] == [node.pid]
    finally:
        node.kill()
        node.wait()


@pytest.mark.skipif(os.geteuid() != 0 or not shutil.which("setpriv"),
                    reason="needs root to start another user's program")
def test_another_users_node_is_found_with_its_user(tmp: Path) -> None:
    folder, lock = stale.hand_folder("velocity_governor.py", tmp)
    os.close(lock)
    node = left_node(folder, 42, NOBODY)
    try:
        assert [(n.pid, n.uid) for n in stale.find(42, tmp)] == [(node.pid, NOBODY)]
    finally:
        node.kill()
        node.wait()


def test_a_domain_someone_is_on_is_not_free() -> None:
    free = stale.free_domain(avoid=0)
    assert free is not None and free != 0
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as bound:  # a participant's
        bound.bind(("127.0.0.1", PORT_BASE + DOMAIN_GAIN * free))
        assert (free, os.geteuid()) in bound_on_domains()
        assert stale.free_domain(avoid=0) != free


def _env(tmp: Path) -> dict[str, str]:
    return {**os.environ, "TMPDIR": str(tmp), "PYTHONPATH": os.pathsep.join(
        filter(None, [str(REPO), os.environ.get("PYTHONPATH")])),
        "AUTOGRADER_LOCK_DIR": str(Path(tempfile.gettempdir()) / "autograder-domains")}


def _command(domain: int, *args: str) -> list[str]:
    return [sys.executable, "-c", "from autograder.cli import main; main()", "sim", "run",
            "--domain", str(domain), "--node", str(NODES / "steady_driver.py"), *args]


@pytest.mark.slow
def test_the_next_hand_run_stops_a_node_a_killed_one_left(ros_domain: int, tmp: Path) -> None:
    killed = subprocess.Popen(_command(ros_domain), env=_env(tmp), stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True)
    left = None
    try:
        assert killed.stdout is not None
        deadline = time.monotonic() + WALL
        for line in killed.stdout:  # the node's first command: it is up and driving
            if found := re.search(r"first command at [\d.]+ s \(pid (\d+)\)", line):
                left = int(found.group(1))
                break
            assert time.monotonic() < deadline, "the node never came up"
        assert left is not None
        killed.kill()  # SIGKILL: no cleanup at all, as an older version's world left it
        killed.wait()
        assert Path(f"/proc/{left}").exists()  # the node lives on, orphaned
        again = subprocess.run(_command(ros_domain, "--duration", "1"), env=_env(tmp),
                               capture_output=True, text=True, timeout=WALL)
    finally:
        if killed.poll() is None:
            killed.kill()
            killed.wait()
    assert again.returncode == 0, again.stdout + again.stderr
    assert (f"A node of yours (steady_driver.py, pid {left}) was still running on ROS "
            f"domain {ros_domain}") in again.stderr
    assert not Path(f"/proc/{left}").exists() or _zombie(left)
    assert [p.name for p in tmp.iterdir() if p.name.startswith(stale.HAND_PREFIX)] == []


def _zombie(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()[0] == "Z"
    except OSError:
        return True


@pytest.mark.slow
@pytest.mark.skipif(os.geteuid() != 0 or not shutil.which("setpriv"),
                    reason="needs root to start another user's program")
def test_a_hand_run_moves_off_a_domain_another_users_node_was_left_on(
        ros_domain: int, tmp: Path) -> None:
    folder, lock = stale.hand_folder("velocity_governor.py", tmp)
    os.close(lock)
    theirs = left_node(folder, ros_domain, NOBODY)
    try:
        done = subprocess.run(_command(ros_domain, "--duration", "1"), env=_env(tmp),
                              capture_output=True, text=True, timeout=WALL)
        assert theirs.poll() is None  # not ours to stop
    finally:
        theirs.kill()
        theirs.wait()
    assert done.returncode == 0, done.stdout + done.stderr
    moved = re.search(rf"Another user's node, left by a hand run, is on ROS domain "
                      rf"{ros_domain}, and only they can stop it: this run uses domain (\d+)",
                      done.stderr)
    assert moved, done.stderr
    assert f"on ROS domain {moved.group(1)}," in done.stdout
