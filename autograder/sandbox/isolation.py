"""How strongly a grading run can isolate the student's program on this machine.

**Strict** (the grader runs as root and may create namespaces): the whole grading run —
world, probe and student — lives in a network namespace of its own holding only
loopback, so the student reaches no network and no other run's graph; the student runs
as a user of its own (uid ``STUDENT_UID_BASE + domain``), in a mount namespace where the
course's hidden tests, solutions and project tests are covered by empty read-only
filesystems, with a size-limited tmpfs as working directory.  Fast DDS then speaks UDP
only: its shared-memory segments, created by root, are not writable by the student's
user, and ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` would cut the student off from a
root peer; the namespace already confines discovery to loopback.

**User** (the grader runs as root where namespaces are refused: Gradescope's container, a
Kubernetes pod, both without ``CAP_SYS_ADMIN``): the student still runs as a user of its
own, switched to with ``CAP_SETUID``/``CAP_SETGID``, which Docker and Kubernetes keep by
default. What namespaces did is done by ownership and mode: the course's protected folders
are closed to other users (:func:`close_to_others`), the student's folder is its own
(0700), and whatever its user leaves is swept (:mod:`autograder.sandbox.sweep`). Fast DDS
speaks UDP on loopback only (:data:`LOOPBACK_PROFILE`): with shared memory the student's
user cannot use segments root made, and ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` cuts a
root participant off from another user's. The program keeps the network
and sees the machine's processes: no namespace can take them away here.

**Basic** (anything else: an ordinary user; ``AUTOGRADER_ISOLATION=basic``): process
group and session, resource limits, cgroups where writable, a throwaway working
directory, ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``. The student runs as the grader's
user and can read, stop and change what the grader can: its results are not official.
"""

from __future__ import annotations

import dataclasses
import os
import shutil
import subprocess
import threading
from pathlib import Path
from typing import Literal

from autograder.core.errors import GraderError
from autograder.i18n import N_
from autograder.sandbox.privileged import PACKAGE_PARENT, SAFE_CWD, module_command
from autograder.sandbox.sweep import STUDENT_UID_BASE

Mode = Literal["strict", "user", "basic"]


@dataclasses.dataclass(frozen=True)
class Isolation:
    """What this machine allows; ``reason`` says why strict isolation is off."""

    mode: Mode
    reason: str = ""
    detail: str = ""

    @property
    def strict(self) -> bool:
        """Namespaces of its own: network, mounts, IPC, /proc (and a user of its own)."""
        return self.mode == "strict"

    @property
    def own_user(self) -> bool:
        """The student runs as a user of its own, not the grader's."""
        return self.mode in ("strict", "user")

    @property
    def official(self) -> bool:
        """Whether the student's program could not read the hidden tests or change the
        result: grades from this shape may go in a gradebook."""
        return self.own_user

    def to_dict(self) -> dict[str, object]:
        return {"mode": self.mode, "official": self.official, "separate_user": self.own_user,
                "network": not self.strict, "hidden_files_protected": self.own_user,
                "reason": self.reason, "detail": self.detail}


def student_uid(domain: int) -> int:
    """A user id of its own for each concurrent run (domains are reserved per run)."""
    return STUDENT_UID_BASE + domain


class Detection:
    """This machine's isolation being found out: the mode to try (``likely``) is known at
    once, the start-up check that confirms it runs meanwhile, and :meth:`result` waits for
    its answer. A grading starts its children in the likely mode while the check runs, and
    lets them grade only once it has confirmed it (:func:`autograder.grading.run.grade`).

    Strict isolation if we are root, namespaces work, and a test program started the way
    every student's program is (:func:`autograder.sandbox.process.student_process`, in the
    run's namespaces) runs Python and rclpy as a user of its own: if the check passes,
    launches work; if not, isolation by user if a test program runs as a user of its own
    without namespaces, else basic isolation, and the reason is kept."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._result: Isolation | None = None
        self._running: subprocess.Popen[str] | None = None
        asked = os.environ.get("AUTOGRADER_ISOLATION")
        if asked == "basic":
            self._result = Isolation(
                "basic", N_("basic isolation was asked for (AUTOGRADER_ISOLATION)"))
        elif os.geteuid() != 0:
            self._result = Isolation("basic", N_("the grader does not run as root"))
        elif asked == "user":
            self.likely = Isolation("user", N_("isolation by user was asked for "
                                               "(AUTOGRADER_ISOLATION)"))
        elif shutil.which("unshare") is None:
            self.likely = Isolation("user", N_("the unshare command (util-linux) is missing"))
        else:
            self.likely = Isolation("strict")
        if self._result is not None:
            self.likely = self._result
        else:
            self._running = start_check(self.likely)

    def result(self) -> Isolation:
        """The isolation the check confirmed (waiting for it), the same at every call."""
        with self._lock:
            if self._result is None:
                assert self._running is not None
                first = _check_answer(self.likely, self._running)
                self._result = first
                if first.mode != self.likely.mode:
                    self._result = _without_namespaces(self.likely, first)
            return self._result


def _without_namespaces(tried: Isolation, failed: Isolation) -> Isolation:
    """What is left when the check of ``tried`` ``failed``: after strict, a user of its own
    if a test program runs as one without namespaces; else basic, with every reason."""
    if not tried.strict:
        return failed
    own = _check(Isolation("user", failed.reason, failed.detail))
    if own.mode == "user":
        return own
    return Isolation("basic", own.reason, " / ".join(d for d in (failed.detail, own.detail)
                                                      if d))


_detection: Detection | None = None
_detection_lock = threading.Lock()


def detection() -> Detection:
    """This process's :class:`Detection`, begun at the first call (a batch's gradings, in
    threads of one process, share it)."""
    global _detection
    with _detection_lock:
        if _detection is None:
            _detection = Detection()
        return _detection


def detect() -> Isolation:
    """This machine's isolation (see :class:`Detection`), waiting for the check."""
    return detection().result()


def forget() -> None:
    """Find the isolation afresh at the next call (tests that set AUTOGRADER_ISOLATION);
    a check under way is waited for first, so that none is left running."""
    global _detection
    with _detection_lock:
        old, _detection = _detection, None
    if old is not None:
        old.result()


def _check(isolation: Isolation) -> Isolation:
    """``isolation`` if a test program runs in it as a student's does; else basic, why."""
    return _check_answer(isolation, start_check(isolation))


def start_check(isolation: Isolation) -> subprocess.Popen[str]:
    """The start-up check of ``isolation``, started."""
    command = [*run_prefix(isolation),
               *module_command("autograder.sandbox.startup_check", [isolation.mode])]
    return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, cwd=SAFE_CWD)


def _check_answer(isolation: Isolation, running: subprocess.Popen[str]) -> Isolation:
    """What the start-up check of ``isolation`` answered: ``isolation`` if it passed."""
    with running:
        try:
            out, err = running.communicate(timeout=120)
        except BaseException as exc:  # stopped, or no answer: it cleans up on SIGTERM
            running.terminate()
            try:
                running.communicate(timeout=10)
            except subprocess.TimeoutExpired:
                running.kill()
            if isinstance(exc, subprocess.TimeoutExpired):
                return Isolation("basic", _could_not(isolation), "no answer within 120 s")
            raise
    command = running.args
    checked = subprocess.CompletedProcess(command, running.returncode, out, err)
    if checked.returncode == 0:
        return isolation
    detail = " / ".join((checked.stdout + checked.stderr).strip().splitlines()[-3:])
    if checked.stderr.startswith("unshare:"):  # the namespaces themselves were refused
        return Isolation("basic", N_("namespaces are not allowed here (an unprivileged "
                                     "container?)"), detail)
    return Isolation("basic", _could_not(isolation), detail)


def _could_not(isolation: Isolation) -> str:
    if isolation.strict:
        return N_("a test program could not run in strict isolation")
    return N_("a test program could not run as a user of its own")


def run_prefix(isolation: Isolation) -> list[str]:
    """The command prefix that puts a whole grading run in its own namespaces."""
    if not isolation.strict:
        return []
    return [shutil.which("unshare") or "unshare", "--net", "--mount", "--propagation",
            "private", "--"]


FASTDDS_PROFILE = Path(__file__).with_name("fastdds_profile.xml")
"""Fast DDS settings for every process of a run: faster participant discovery (the file
says why). A student's program gets a copy in its working directory (process.py): in
strict isolation it cannot read the grader's package."""
LOOPBACK_PROFILE = Path(__file__).with_name("fastdds_loopback.xml")
"""The same settings, and UDP on 127.0.0.1 as the only transport: isolation by user, where
no network namespace keeps discovery on loopback."""
PROFILE_ENV = "FASTRTPS_DEFAULT_PROFILES_FILE"  # Fast DDS 2.x, Jazzy's middleware


def dds_env(isolation: Isolation) -> dict[str, str | None]:
    """Middleware settings for every process of the run (None: unset)."""
    if isolation.mode == "user":  # the profile's transport, nothing built in
        return {"FASTDDS_BUILTIN_TRANSPORTS": None, "ROS_AUTOMATIC_DISCOVERY_RANGE": None,
                PROFILE_ENV: str(LOOPBACK_PROFILE)}
    profile = {PROFILE_ENV: str(FASTDDS_PROFILE)}
    if isolation.strict:
        return {"FASTDDS_BUILTIN_TRANSPORTS": "UDPv4", "ROS_AUTOMATIC_DISCOVERY_RANGE": None,
                **profile}
    return {"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST", **profile}


def bring_up_loopback() -> None:
    """Set ``lo`` up in a fresh network namespace (ioctl; no iproute2 needed)."""
    import fcntl
    import socket
    import struct

    siocgifflags, siocsifflags, iff_up = 0x8913, 0x8914, 0x1
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        request = struct.pack("16sH22x", b"lo", 0)
        flags = struct.unpack("16sH22x", fcntl.ioctl(sock, siocgifflags, request))[1]
        fcntl.ioctl(sock, siocsifflags, struct.pack("16sH22x", b"lo", flags | iff_up))


def protected_paths(course: Path) -> list[Path]:
    """What the student must not read: hidden tests, solutions, quiz keys, our own tests
    and history — in the course being graded and in the checkout the platform runs from."""
    roots = dict.fromkeys((course.resolve(), Path(PACKAGE_PARENT)))
    return [p for root in roots for p in (root / "assignments", root / "tests", root / ".git",
                                          root / "quizzes") if p.exists()]


def close_to_others(paths: list[Path]) -> list[Path]:
    """Take every permission of other users off each of ``paths`` (the folder itself:
    nobody else gets into it, whatever it holds); the ones changed. For isolation by user,
    where no mount namespace covers them: a student's user is "other" to every file of
    the grader's (it has no group but its own)."""
    changed = []
    for path in paths:
        mode = path.lstat().st_mode
        if mode & 0o007 and not path.is_symlink():
            try:
                path.chmod(mode & 0o7770)
            except OSError as exc:  # a read-only mount: it must come closed
                raise GraderError(
                    f"{path} is open to other users and cannot be closed ({exc.strerror}): "
                    f"a student's program could read it. Make it the grader's, mode 0700 "
                    f"(or 0750), before grading.") from None
            changed.append(path)
    return changed
