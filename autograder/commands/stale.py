"""Nodes left on a ROS domain by a hand run that did not end (``sim run --node`` killed
with SIGKILL, or run by a version that left its node behind).

A hand run's folder (``$TMPDIR/autograder-hand-*``) holds a lock its world keeps for as
long as it runs; a program whose working directory is in a hand folder that no world holds
is stale. Such a node still relays its commands, so the next hand run on its domain would
have two governors: the student's own are stopped (and their folders removed), and where
another user's is on the domain, the run moves to a free domain instead.
"""

from __future__ import annotations

import contextlib
import dataclasses
import fcntl
import os
import select
import shutil
import signal
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

HAND_PREFIX = "autograder-hand-"
LOCK_NAME = ".world.lock"
# Wall seconds a stale node has to end after SIGINT before it is killed.
GRACE = 2.0


@dataclasses.dataclass(frozen=True)
class StaleNode:
    """A program left running in a hand run's folder."""

    pid: int
    uid: int
    folder: Path  # the hand run's folder
    script: str  # the file it runs, as its command line names it ("" if none does)


def hand_folder(script: str, parent: Path | None = None) -> tuple[Path, int]:
    """A new hand run's folder and the descriptor of its lock, held until it is closed
    (its programs do not inherit it: Python's descriptors are not inheritable). The lock
    file names ``script``, the file the run runs."""
    folder = Path(tempfile.mkdtemp(prefix=HAND_PREFIX, dir=parent))
    fd = os.open(folder / LOCK_NAME, os.O_RDWR | os.O_CREAT, 0o600)
    fcntl.flock(fd, fcntl.LOCK_EX)
    os.write(fd, script.encode())
    return folder, fd


def _held(folder: Path) -> bool | None:
    """Whether a live world holds ``folder``'s lock; None where there is no lock to try
    (an older version's folder, or another user's we cannot open)."""
    try:
        fd = os.open(folder / LOCK_NAME, os.O_RDWR)
    except OSError:
        return None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return True
    finally:
        os.close(fd)
    return False


def _processes(proc: Path = Path("/proc")) -> Iterator[tuple[int, int, Path]]:
    """(pid, uid, working directory) of every process whose directory can be read."""
    for entry in proc.iterdir():
        if not entry.name.isdigit():
            continue
        try:
            cwd = Path(os.readlink(entry / "cwd"))
            uid = entry.stat().st_uid
        except OSError:
            continue
        yield int(entry.name), uid, cwd


def _domain_of(pid: int) -> int | None:
    """The ROS domain process ``pid`` is on (its ``ROS_DOMAIN_ID``, 0 if unset)."""
    try:
        environ = Path(f"/proc/{pid}/environ").read_bytes().split(b"\0")
    except OSError:
        return None
    for item in environ:
        if item.startswith(b"ROS_DOMAIN_ID="):
            try:
                return int(item.partition(b"=")[2])
            except ValueError:
                return 0
    return 0


def _script(pid: int, folder: Path) -> str:
    """The file the program runs: as its command line names it, else as its hand run's
    lock file says (a program forked from a zygote has the zygote's command line)."""
    try:
        args = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
    except OSError:
        args = []
    named = [a for a in args if a.endswith(b".py") and HAND_PREFIX.encode() in a]
    if named:
        return Path(named[0].decode(errors="replace")).name
    try:
        return (folder / LOCK_NAME).read_text(encoding="utf-8", errors="replace").strip()
    except OSError:
        return ""


def working_in(folder: Path) -> list[StaleNode]:
    """The programs this process can see working in hand folder ``folder`` (a run's own
    backstop: one forked while it was being stopped is found here)."""
    return [StaleNode(pid, uid, folder, "") for pid, uid, cwd in _processes()
            if (cwd == folder or folder in cwd.parents) and pid != os.getpid()]


def find(domain: int, tmp: Path | None = None) -> list[StaleNode]:
    """The stale programs on ``domain`` that this process can see (its user's; everyone's
    for root)."""
    tmp = Path(tmp or tempfile.gettempdir())
    found = []
    for pid, uid, cwd in _processes():
        if cwd.parent == tmp and cwd.name.startswith(HAND_PREFIX):
            folder = cwd
        elif cwd.parent.parent == tmp and cwd.parent.name.startswith(HAND_PREFIX):
            folder = cwd.parent
        else:
            continue
        if pid == os.getpid() or _held(folder) or _domain_of(pid) != domain:
            continue
        found.append(StaleNode(pid, uid, folder, _script(pid, folder)))
    return found


def stop(nodes: list[StaleNode]) -> None:
    """Stop ``nodes`` (SIGINT to each one's process group, as Ctrl-C would; SIGKILL to
    what is left after :data:`GRACE` seconds) and remove their folders."""
    for sig in (signal.SIGINT, signal.SIGKILL):
        for node in nodes:
            for kill in (os.killpg, os.kill):
                with contextlib.suppress(ProcessLookupError, PermissionError):
                    kill(node.pid, sig)
        if _wait_gone([n.pid for n in nodes], GRACE):
            break
    for folder in {n.folder for n in nodes}:
        shutil.rmtree(folder, ignore_errors=True)


def _wait_gone(pids: list[int], seconds: float) -> bool:
    """Wait until every one of ``pids`` (not our children) has exited, at most
    ``seconds``; whether they all have. A pidfd becomes readable when its process ends."""
    fds = []
    for pid in pids:
        with contextlib.suppress(ProcessLookupError):
            fds.append(os.pidfd_open(pid))
    deadline = time.monotonic() + seconds
    try:
        while fds:
            ready, _w, _x = select.select(fds, [], [], max(0.0, deadline - time.monotonic()))
            if not ready:
                return False
            for fd in ready:
                fds.remove(fd)
                os.close(fd)
        return True
    finally:
        for fd in fds:
            os.close(fd)


def free_domain(avoid: int) -> int | None:
    """A domain no one is on (no UDP socket bound to its ports), other than ``avoid``;
    None if all 233 are in use."""
    from autograder.sandbox.domains import bound_on_domains

    taken = {domain for domain, _uid in bound_on_domains()} | {avoid}
    return next((d for d in range(233) if d not in taken), None)
