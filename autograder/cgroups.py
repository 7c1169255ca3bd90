"""Control groups for a student's program: bound its processes and memory, and kill all of
it, daemons that left its session included.

v1 only for now: a ``pids`` and a ``memory`` hierarchy under ``AUTOGRADER_CGROUP_ROOT``
(default ``/sys/fs/cgroup``), used where the machine lets us create groups there.
"""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

from autograder.exercise import Limits

_CGROUP_ROOT = Path(os.environ.get("AUTOGRADER_CGROUP_ROOT", "/sys/fs/cgroup"))

class Cgroup:
    """A v1 cgroup per controller (``pids``, ``memory``), created when the machine allows."""

    def __init__(self, name: str, limits: Limits) -> None:
        self.paths: list[Path] = []
        for controller, settings in (
            ("pids", {"pids.max": str(limits.processes)}),
            ("memory", {"memory.limit_in_bytes": str(limits.memory_mb * 1024 * 1024)}),
        ):
            path = _CGROUP_ROOT / controller / "autograder" / name
            try:
                path.mkdir(parents=True, exist_ok=True)
                for key, value in settings.items():
                    (path / key).write_text(value)
            except OSError:
                continue
            self.paths.append(path)

    @classmethod
    def existing(cls, paths: list[str]) -> Cgroup:
        """A run's cgroups known by path (to reap them from another process)."""
        group = cls.__new__(cls)
        group.paths = [Path(p) for p in paths]
        return group

    @property
    def available(self) -> bool:
        return bool(self.paths)

    def pids(self) -> set[int]:
        found: set[int] = set()
        for path in self.paths:
            try:
                found |= {int(p) for p in (path / "cgroup.procs").read_text().split()}
            except OSError:
                pass
        return found

    def kill_all(self) -> None:
        """SIGKILL every process in the cgroup until none is left (bounded)."""
        for _attempt in range(50):
            pids = self.pids()
            if not pids:
                return
            for pid in pids:
                try:
                    os.kill(pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
            time.sleep(0.02)

    def remove(self) -> None:
        for path in self.paths:
            try:
                path.rmdir()
            except OSError:
                pass
