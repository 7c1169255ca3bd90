"""Control groups for a student's program: bound its processes and memory, and kill all of
it, daemons that left its session included.

Where the groups live
    Under ``AUTOGRADER_CGROUP_ROOT`` (default ``/sys/fs/cgroup``), read at each use.  The
    hierarchy is detected there: a ``cgroup.controllers`` file means cgroup **v2** (the
    unified hierarchy), anything else is taken as **v1**.

v1
    One group per controller: ``<root>/pids/autograder/<name>`` (``pids.max``),
    ``<root>/memory/autograder/<name>`` (``memory.limit_in_bytes``) and
    ``<root>/cpu/autograder-<name>`` (``cpu.shares``, the default: a share of its own,
    at the top of the hierarchy).  The controller
    folders must already be mounted; nothing here creates them.

v2
    One leaf per run, ``<root>/autograder/<name>``, with ``pids.max``, ``memory.max`` and
    ``cpu.weight`` (the default; the students together then weigh as much as the
    ``autograder`` folder's siblings, the grader's own processes among them). For those
    files to exist, the controllers must be enabled in the
    ``cgroup.subtree_control`` of ``<root>`` and of ``<root>/autograder``; they are
    enabled there when the root offers them (its ``cgroup.controllers``).  The kernel's
    "no internal processes" rule refuses that (EBUSY) in a non-root group that holds
    processes: the controller is then not used, and no process is ever moved to make room.
    Killing writes ``1`` to the leaf's ``cgroup.kill`` (kernel 5.14+), then SIGKILLs
    whatever ``cgroup.procs`` still lists, as on v1.

Delegation (v2, for an instructor)
    The grader needs a cgroup2 folder it may write, holding none of its own processes, and
    ``AUTOGRADER_CGROUP_ROOT`` pointing at it.

    * systemd: run the grader as a service with ``Delegate=pids memory cpu`` (or ``yes``) and
      ``DelegateSubgroup=supervisor`` (systemd 254+; it keeps the service's own processes
      in a child group), then set ``AUTOGRADER_CGROUP_ROOT`` to the service's folder, e.g.
      ``/sys/fs/cgroup/system.slice/autograder.service``.  A grader that is not root also
      needs ``User=`` there so the delegated folder is its own.
    * Docker: ``--cgroupns=private`` with a writable cgroup mount (``--privileged``, or a
      rw bind of the container's group).  The container's processes sit in its root
      group, so the entrypoint must first move itself into a child (``mkdir
      /sys/fs/cgroup/init`` and write its pid there) before the grader can enable
      controllers; the grader itself does not do this.

Where nothing is writable
    No group is created; the launcher's resource limits still apply: RLIMIT_AS bounds
    memory, and RLIMIT_NPROC bounds processes when the student runs as a uid of its own
    (for root, or for a uid shared with the grader, it bounds nothing of the student's
    alone).  Daemons that leave the session are then found by uid, not by group.
    :func:`describe_bounds` says which of these were in force, for the results.
"""

from __future__ import annotations

import os
import signal
import time
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any, Literal

from autograder.core.exercise import Limits

Version = Literal["v1", "v2"]
# ``cpu`` sets no limit: a group of its own makes the program one entity for the CPU
# scheduler whatever it forks, so a student's spinning children take one share, not one
# per child, from the gradings running beside it.
CONTROLLERS = ("pids", "memory", "cpu")
# The file that carries each controller's limit, per hierarchy.
LIMIT_FILES: dict[Version, dict[str, str]] = {
    "v1": {"pids": "pids.max", "memory": "memory.limit_in_bytes", "cpu": "cpu.shares"},
    "v2": {"pids": "pids.max", "memory": "memory.max", "cpu": "cpu.weight"},
}
# The default share of each hierarchy: every program the same.
CPU_SHARE: dict[Version, str] = {"v1": "1024", "v2": "100"}
PARENT = "autograder"


def cgroup_root() -> Path:
    """The cgroup root, read from the environment at each call (not frozen at import)."""
    return Path(os.environ.get("AUTOGRADER_CGROUP_ROOT", "/sys/fs/cgroup"))


def hierarchy(root: Path) -> Version:
    """v2 where ``root`` is a cgroup2 folder (it lists its ``cgroup.controllers``), else v1."""
    return "v2" if (root / "cgroup.controllers").exists() else "v1"


def _limit_values(limits: Limits, version: Version) -> dict[str, str]:
    return {"pids": str(limits.processes), "memory": str(limits.memory_mb * 1024 * 1024),
            "cpu": CPU_SHARE[version]}


def _v1_folder(mount: Path, controller: str, name: str) -> Path:
    """Where a run's v1 group of ``controller`` lives. ``cpu`` groups sit at the top of
    their hierarchy, beside the grader's own processes: under a shared parent, every
    student of every grading would weigh as one thread of the grader's, and a batch's
    programs would starve."""
    return mount / (f"{PARENT}-{name}" if controller == "cpu" else f"{PARENT}/{name}")


def write_control(path: Path, value: str) -> None:
    """Write ``value`` to a cgroup control file in one ``write()``: cgroupfs parses each
    write on its own. Raises OSError as the kernel refuses it (a busy controller)."""
    with open(path, "w") as fh:
        fh.write(value)


def _try_write(path: Path, value: str) -> bool:
    try:
        write_control(path, value)
    except OSError:
        return False
    return True


def _listed(path: Path) -> set[str]:
    """The names in a controller list file (``cgroup.controllers``, ``subtree_control``)."""
    try:
        return set(path.read_text().split())
    except OSError:
        return set()


def _rmdir(path: Path) -> None:
    try:
        path.rmdir()
    except OSError:
        pass


def _enable(group: Path, wanted: set[str]) -> set[str]:
    """Enable ``wanted`` for ``group``'s children; the ones that are enabled afterwards."""
    control = group / "cgroup.subtree_control"
    listed = _listed(control)
    missing = [c for c in CONTROLLERS if c in wanted and c not in listed]
    if not missing or _try_write(control, " ".join(f"+{c}" for c in missing)):
        return set(wanted)
    # The kernel takes a write whole or not at all: one at a time, so a controller it
    # refuses (EBUSY, EINVAL) does not cost the other.
    return {c for c in wanted if c in listed or _try_write(control, f"+{c}")}


def _create_v1(root: Path, name: str, limits: Limits) -> tuple[list[Path], set[str]]:
    paths: list[Path] = []
    controllers: set[str] = set()
    values = _limit_values(limits, "v1")
    for controller in CONTROLLERS:
        mount = root / controller
        if not mount.is_dir():
            continue  # not mounted: creating the folder would make a plain directory
        path = _v1_folder(mount, controller, name)
        try:
            path.mkdir(parents=True, exist_ok=True)
            write_control(path / LIMIT_FILES["v1"][controller], values[controller])
        except OSError:
            _rmdir(path)
            continue
        paths.append(path)
        controllers.add(controller)
    return paths, controllers


def _create_v2(root: Path, name: str, limits: Limits) -> tuple[list[Path], set[str]]:
    parent = root / PARENT
    leaf = parent / name
    try:
        parent.mkdir(exist_ok=True)
    except OSError:
        return [], set()  # not ours to write: leave the root's subtree_control alone too
    offered = _listed(root / "cgroup.controllers") & set(CONTROLLERS)
    usable = _enable(parent, _enable(root, offered))
    try:
        leaf.mkdir(exist_ok=True)
    except OSError:
        return [], set()
    values = _limit_values(limits, "v2")
    # A leaf without controllers is still kept: it holds every process the student starts,
    # so cgroup.kill and cgroup.procs reach daemons that left the session.
    controllers = {c for c in usable
                   if _try_write(leaf / LIMIT_FILES["v2"][c], values[c])}
    return [leaf], controllers


def _version_of(paths: list[Path]) -> Version | None:
    """A group's hierarchy from its folders: only v2 groups have these files."""
    if not paths:
        return None
    v2 = any((p / "cgroup.kill").exists() or (p / "cgroup.controllers").exists()
             for p in paths)
    return "v2" if v2 else "v1"


def _alive(pid: int) -> bool:
    """Whether ``pid`` still runs.  A zombie does not: it holds nothing, its parent reaps it,
    and waiting for it to leave ``cgroup.procs`` would only spin until the bound."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except (FileNotFoundError, ProcessLookupError):
        return False
    except OSError:
        return True  # unreadable (hidepid): assume it runs, the kill loop is bounded anyway
    return stat.rpartition(")")[2].split()[0] != "Z"


class Cgroup:
    """The cgroup(s) of one run, created where the machine allows.

    ``paths`` are the folders a process joins (by writing its pid to ``cgroup.procs``):
    one per controller on v1, one leaf on v2, none where nothing was writable.
    ``version`` is ``"v1"``, ``"v2"`` or None (no group); ``controllers`` are the ones
    whose limit or share was set (``pids``, ``memory``, ``cpu``).
    """

    def __init__(self, name: str, limits: Limits) -> None:
        root = cgroup_root()
        version = hierarchy(root)
        create = _create_v2 if version == "v2" else _create_v1
        paths, controllers = create(root, name, limits)
        self.paths: list[Path] = paths
        self.controllers: frozenset[str] = frozenset(controllers)
        self.version: Version | None = version if paths else None

    @classmethod
    def existing(cls, paths: Iterable[str]) -> Cgroup:
        """A run's cgroups known by path (to reap them from another process).

        The hierarchy and controllers are read back from the folders where they still
        exist; a removed group reads as v1 without controllers, which kills nothing less.
        """
        group = cls.__new__(cls)
        group.paths = [Path(p) for p in paths]
        group.version = _version_of(group.paths)
        files = LIMIT_FILES[group.version or "v1"]
        group.controllers = frozenset(
            c for c in CONTROLLERS if any((p / files[c]).exists() for p in group.paths))
        return group

    @property
    def available(self) -> bool:
        return bool(self.paths)

    def info(self) -> dict[str, Any]:
        """What was set up, JSON-serializable: ``{"version", "controllers", "paths"}``."""
        return {"version": self.version, "controllers": sorted(self.controllers),
                "paths": [str(p) for p in self.paths]}

    def bounds(self, separate_uid: bool) -> dict[str, str | None]:
        """:func:`describe_bounds` of this group."""
        return describe_bounds(self.info(), separate_uid)

    def pids(self) -> set[int]:
        found: set[int] = set()
        for path in self.paths:
            try:
                found |= {int(p) for p in (path / "cgroup.procs").read_text().split()}
            except OSError:
                pass
        return found

    def kill_all(self) -> bool:
        """Kill every process in the group; whether none is left running.

        v2's ``cgroup.kill`` kills the whole group at once, forks in flight included; the
        loop then SIGKILLs what is still listed (v1, older kernels, a slow exit), bounded.
        """
        for path in self.paths:
            if (path / "cgroup.kill").exists():
                _try_write(path / "cgroup.kill", "1")
        for _attempt in range(50):
            pids = {pid for pid in self.pids() if _alive(pid)}
            if not pids:
                return True
            for pid in pids:
                try:
                    os.kill(pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
            time.sleep(0.02)
        return not any(_alive(pid) for pid in self.pids())

    def remove(self) -> None:
        """Remove the run's folders (the shared ``autograder`` parent stays)."""
        for path in self.paths:
            _rmdir(path)


def describe_bounds(cgroup_info: Mapping[str, Any] | None,
                    separate_uid: bool) -> dict[str, str | None]:
    """Which bounds were in force for a run, for its results (JSON-serializable).

    ``cgroup_info`` is :meth:`Cgroup.info` (None when no group was attempted);
    ``separate_uid`` whether the student ran as a uid of its own, the only case where
    RLIMIT_NPROC counts the student's processes alone.  Returns::

        {"cgroup": "v2" | "v1" | None,         # the hierarchy the program ran in
         "processes": "cgroup" | "rlimit" | None,
         "memory": "cgroup" | "rlimit",        # RLIMIT_AS always applies besides
         "cpu": "cgroup" | None}               # a CPU share of its own
    """
    info = cgroup_info or {}
    controllers = set(info.get("controllers", ()))
    processes = "cgroup" if "pids" in controllers else "rlimit" if separate_uid else None
    memory = "cgroup" if "memory" in controllers else "rlimit"
    return {"cgroup": info.get("version"), "processes": processes, "memory": memory,
            "cpu": "cgroup" if "cpu" in controllers else None}
