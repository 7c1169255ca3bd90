"""End everything of a student's user once its programs are done: the processes that
left their process group and cgroup (or ran where no cgroup could be made), and the SysV
IPC objects, POSIX message queues and files in the shared scratch folders it made.

Only for a user of the student's own (strict isolation and isolation by user give each
run one): never root, never the grader's user.  The kill is sent *as* that user,
``kill(-1, SIGKILL)``, which
the kernel delivers to every process the sender may signal (all of that user's, itself
excepted) in one pass, so a program forking as fast as it can is not raced pid by pid.
In strict isolation the program's IPC objects and ``/tmp`` are its own namespace's and go
with it; the sweep is for where there is no namespace to take them.

A sweep ends when the user has no task left at all, its zombies included: a killed process
still counts against its user's ``RLIMIT_NPROC`` until its parent (for an orphan, the
zygote or the machine's init) has reaped it, and the next program of that user (the next
grading on the same ROS domain) would find its budget spent by the last one's fork bomb.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import subprocess
import sys
import time

from autograder.sandbox.contained.launcher import process_statuses

_KILL_ALL = "import os, signal; os.kill(-1, signal.SIGKILL)"

STUDENT_UID_BASE = 200_000
"""Strict isolation runs a student as ``STUDENT_UID_BASE + domain``, a user of its own."""
ROS_DOMAINS = 233  # ROS domain ids 0..232: Fast DDS's ports end there


def is_student_uid(uid: int) -> bool:
    """Whether ``uid`` is one of the students' own users (the only ones swept)."""
    return STUDENT_UID_BASE <= uid < STUDENT_UID_BASE + ROS_DOMAINS


def user_processes(uid: int, proc: str = "/proc") -> list[int]:
    """The live processes (not zombies) whose real user is ``uid``."""
    return [pid for pid, owner, state, _threads in process_statuses(proc)
            if owner == uid and state != b"Z"]


def kill_user(uid: int, timeout: float = 30.0) -> bool:
    """SIGKILL every process of ``uid`` until none is left and none of them is still
    counted against the user's ``RLIMIT_NPROC`` (or ``timeout`` wall seconds pass); whether
    the user has no task left but the caller's own children's zombies, which are the
    caller's to reap. A killed process is listed until the kernel has freed it and its
    parent has reaped it, which a busy machine, or an init reaping a fork bomb's orphans,
    can take seconds over: the wait is for that, not for the kill."""
    if not is_student_uid(uid) or uid in (os.getuid(), os.geteuid()):
        raise ValueError(f"will not sweep uid {uid}: not a student's own user")
    deadline = time.monotonic() + timeout
    setpriv = shutil.which("setpriv")
    pause = 0.01  # doubled up to 0.1 s: a scan of /proc costs milliseconds of CPU
    while True:
        tasks = [(pid, state) for pid, owner, state, _threads in process_statuses()
                 if owner == uid]
        pids = [pid for pid, state in tasks if state != b"Z"]
        if not pids and all(parent_of(pid) == os.getpid() for pid, _state in tasks):
            return True
        if time.monotonic() > deadline:
            return False
        # With only zombies left there is nothing to kill: their parents reap them.
        if pids and setpriv is not None:
            subprocess.run([setpriv, f"--reuid={uid}", f"--regid={uid}", "--clear-groups",
                            sys.executable, "-I", "-S", "-c", _KILL_ALL], cwd="/",
                           stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL, env={}, check=False)
        else:  # pid by pid: the run's RLIMIT_NPROC bounds how many there can be
            for pid in pids:
                try:
                    os.kill(pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
        time.sleep(pause)
        pause = min(2 * pause, 0.1)


def parent_of(pid: int, proc: str = "/proc") -> int | None:
    """The parent of ``pid`` now; None once it is gone."""
    try:
        with open(f"{proc}/{pid}/stat", "rb") as fh:
            return int(fh.read().rpartition(b")")[2].split()[1])
    except (OSError, IndexError, ValueError):
        return None


# The machine's shared scratch folders, where a program without a mount namespace of its
# own can leave files (POSIX shared memory is files in /dev/shm; queues in /dev/mqueue).
SCRATCH = ("/tmp", "/var/tmp", "/dev/shm", "/dev/mqueue")
# /proc/sysvipc/<kind>: the column of each object's id.
_SYSV = {"shm": "shmid", "msg": "msqid", "sem": "semid"}


def user_ipc(uid: int, proc: str = "/proc") -> list[tuple[str, int]]:
    """The SysV IPC objects (kind, id) owned or created by ``uid``, in this namespace."""
    found = []
    for kind, id_column in _SYSV.items():
        try:
            with open(f"{proc}/sysvipc/{kind}") as fh:
                header, *rows = [line.split() for line in fh]
        except OSError:
            continue
        for row in rows:
            fields = dict(zip(header, row, strict=False))
            with contextlib.suppress(KeyError, ValueError):
                if uid in (int(fields["uid"]), int(fields["cuid"])):
                    found.append((kind, int(fields[id_column])))
    return found


# Run as the student's user: it owns what it made. Root without CAP_SYS_ADMIN (a container's)
# may not remove another user's IPC objects, and without CAP_DAC_OVERRIDE (a Kubernetes
# pod's) could not even list a 0700 folder of another user's. Arguments: "shm:ID",
# "msg:ID", "sem:ID", or a path.
_CLEAN = """\
import ctypes, os, shutil, stat, sys
libc = ctypes.CDLL(None)
for item in sys.argv[1:]:
    kind, _, ident = item.partition(":")
    try:
        if kind == "sem":
            libc.semctl(int(ident), 0, 0)  # IPC_RMID
        elif kind in ("shm", "msg"):
            getattr(libc, kind + "ctl")(int(ident), 0, None)  # IPC_RMID
        elif os.path.isdir(item) and not os.path.islink(item):
            os.chmod(item, stat.S_IRWXU)  # folders it made closed: its own to open again
            for root, dirs, _files in os.walk(item):
                for name in dirs:
                    if not os.path.islink(os.path.join(root, name)):
                        os.chmod(os.path.join(root, name), stat.S_IRWXU)
            shutil.rmtree(item, ignore_errors=True)
        else:
            os.unlink(item)
    except (OSError, ValueError):
        pass
"""


def user_files(uid: int, folders: tuple[str, ...] = SCRATCH) -> list[str]:
    """What ``uid`` owns at the top of each scratch folder."""
    found = []
    for folder in folders:
        try:
            entries = list(os.scandir(folder))
        except OSError:
            continue
        for entry in entries:
            with contextlib.suppress(OSError):
                if entry.stat(follow_symlinks=False).st_uid == uid:
                    found.append(entry.path)
    return found


def remove_leftovers(uid: int, folders: tuple[str, ...] = SCRATCH) -> None:
    """Remove every SysV IPC object of ``uid`` (a segment still attached goes once
    detached: its last user is dead by now) and what it owns at the top of each scratch
    folder (a folder with all in it; links themselves, never what they point to), acting
    as ``uid``: after the sweep's kill nothing of it runs to race the removal."""
    items = [f"{kind}:{ident}" for kind, ident in user_ipc(uid)] + user_files(uid, folders)
    setpriv = shutil.which("setpriv")
    if not items or setpriv is None:
        return
    subprocess.run([setpriv, f"--reuid={uid}", f"--regid={uid}", "--clear-groups",
                    sys.executable, "-I", "-S", "-c", _CLEAN, *items], cwd="/",
                   stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL, env={}, check=False, timeout=60)


def sweep_user(uid: int) -> bool:
    """End every process of the student's ``uid``, then remove its IPC objects and scratch
    files; whether no task of it was left (see :func:`kill_user`)."""
    gone = kill_user(uid)
    remove_leftovers(uid)
    return gone
