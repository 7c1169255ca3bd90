"""How strongly a grading run can isolate the student's program on this machine.

**Strict** (the grader runs as root and may create namespaces): the whole grading run —
world, probe and student — lives in a network namespace of its own holding only
loopback, so the student reaches no network and no other run's graph; the student runs
as a user of its own (uid ``STUDENT_UID_BASE + domain``), in a mount namespace where the
course's hidden tests, solutions and project tests are covered by empty read-only
filesystems, with a size-limited tmpfs as working directory.  Fast DDS then speaks UDP
only: its shared-memory segments, created by root, are not writable by the student's
user and traffic silently stops (measured), and ``ROS_AUTOMATIC_DISCOVERY_RANGE=
LOCALHOST`` also cut the student off from a root peer (measured), while the namespace
already confines discovery to loopback.

**Basic** (anything else): process group and session, resource limits, cgroups where
writable, a throwaway working directory, ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``.
The student runs as the grader's user and can read what the grader can; results say so.
"""

from __future__ import annotations

import dataclasses
import functools
import os
import shutil
import subprocess
import sys
from pathlib import Path

from autograder.i18n import N_

STUDENT_UID_BASE = 200_000


@dataclasses.dataclass(frozen=True)
class Isolation:
    """What this machine allows; ``reason`` says why strict isolation is off."""

    strict: bool
    reason: str = ""
    detail: str = ""

    @property
    def mode(self) -> str:
        return "strict" if self.strict else "basic"

    def to_dict(self) -> dict[str, object]:
        return {"mode": self.mode, "separate_user": self.strict, "network": not self.strict,
                "hidden_files_protected": self.strict, "reason": self.reason,
                "detail": self.detail}


def student_uid(domain: int) -> int:
    """A user id of its own for each concurrent run (domains are reserved per run)."""
    return STUDENT_UID_BASE + domain


@functools.cache
def detect() -> Isolation:
    """Strict isolation if we are root, namespaces work, and an unprivileged user can run
    this Python and import rclpy (a venv under /root, mode 0700, is out of its reach)."""
    if os.environ.get("AUTOGRADER_ISOLATION") == "basic":
        return Isolation(False, N_("basic isolation was asked for (AUTOGRADER_ISOLATION)"))
    if os.geteuid() != 0:
        return Isolation(False, N_("the grader does not run as root"))
    unshare = shutil.which("unshare")
    if unshare is None:
        return Isolation(False, N_("the unshare command (util-linux) is missing"))
    probe = subprocess.run(
        [unshare, "--net", "--mount", "--propagation", "private", "--", sys.executable,
         "-m", "autograder.sandbox_exec", "--check", str(student_uid(0))],
        capture_output=True, text=True, timeout=60,
        env=dict(os.environ, PYTHONPATH=_package_parent()))
    if probe.returncode != 0:
        detail = (probe.stderr or probe.stdout).strip().splitlines()
        return Isolation(False, N_("an unprivileged user cannot run this Python and rclpy "
                                   "(make the virtual environment readable by all)"),
                         detail[-1] if detail else "")
    return Isolation(True)


def _package_parent() -> str:
    return str(Path(__file__).resolve().parent.parent)


def run_prefix(isolation: Isolation) -> list[str]:
    """The command prefix that puts a whole grading run in its own namespaces."""
    if not isolation.strict:
        return []
    return [shutil.which("unshare") or "unshare", "--net", "--mount", "--propagation",
            "private", "--"]


def dds_env(isolation: Isolation) -> dict[str, str | None]:
    """Middleware settings for every process of the run (None: unset)."""
    if isolation.strict:
        return {"FASTDDS_BUILTIN_TRANSPORTS": "UDPv4", "ROS_AUTOMATIC_DISCOVERY_RANGE": None}
    return {"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}


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
    roots = dict.fromkeys((course.resolve(), Path(_package_parent())))
    return [p for root in roots for p in (root / "assignments", root / "tests", root / ".git",
                                          root / "quizzes") if p.exists()]
