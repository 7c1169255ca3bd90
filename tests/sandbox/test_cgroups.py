"""Cgroups v1 and v2 (autograder.sandbox.cgroups): v2 on a fake cgroupfs tree, since the machines
that run this suite may be v1; v1 on a fake tree and, as root, on the machine's own."""

from __future__ import annotations

import errno
import json
import os
import signal
import subprocess
import time
import uuid
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from autograder.core.exercise import Limits
from autograder.sandbox import cgroups
from autograder.sandbox.cgroups import Cgroup, cgroup_root, describe_bounds, hierarchy

LIMITS = Limits(processes=32, memory_mb=100)
MEMORY_BYTES = str(100 * 1024 * 1024)


def _until(condition: Callable[[], bool], what: str, deadline: float = 10.0) -> None:
    end = time.monotonic() + deadline
    while not condition():
        assert time.monotonic() < end, f"not within {deadline}s: {what}"
        time.sleep(0.01)


@pytest.fixture
def children() -> Iterator[list[subprocess.Popen[bytes]]]:
    """Children a test starts; none outlives it, whatever it asserts."""
    started: list[subprocess.Popen[bytes]] = []
    yield started
    for child in started:
        if child.poll() is None:
            child.kill()
        child.wait(5)


def _join(group: Cgroup, started: list[subprocess.Popen[bytes]]) -> subprocess.Popen[bytes]:
    """A child that joins the group as the launcher does (its own pid into ``cgroup.procs``
    of each folder), then becomes a ``sleep``; returned once the group lists it."""
    script = 'for g in "$@"; do echo $$ > "$g/cgroup.procs" || exit 1; done; exec sleep 60'
    child = subprocess.Popen(["sh", "-c", script, "sh", *map(str, group.paths)])
    started.append(child)
    _until(lambda: child.poll() is not None or child.pid in group.pids(), "joined")
    assert child.poll() is None, "the child could not join the group"
    return child


def _assert_killed(child: subprocess.Popen[bytes]) -> None:
    assert child.wait(timeout=10) == -signal.SIGKILL


@pytest.fixture
def v2_root(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A fake cgroup2 root offering pids and memory, nothing enabled yet."""
    root = tmp_path / "cgroup2"
    root.mkdir()
    (root / "cgroup.controllers").write_text("cpuset cpu io memory pids\n")
    (root / "cgroup.subtree_control").write_text("")
    (root / "cgroup.procs").write_text("")
    monkeypatch.setenv("AUTOGRADER_CGROUP_ROOT", str(root))
    return root


@pytest.fixture
def v1_root(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A fake v1 root: the pids and memory hierarchies mounted, nothing else."""
    root = tmp_path / "cgroup1"
    (root / "pids").mkdir(parents=True)
    (root / "memory").mkdir()
    monkeypatch.setenv("AUTOGRADER_CGROUP_ROOT", str(root))
    return root


def _kernel_leaf(root: Path, name: str) -> Path:
    """The leaf as the kernel makes it on mkdir: its interface files (5.14+ has cgroup.kill)."""
    leaf = root / "autograder" / name
    leaf.mkdir(parents=True)
    for interface in ("cgroup.controllers", "cgroup.procs", "cgroup.kill"):
        (leaf / interface).write_text("")
    return leaf


def test_hierarchy_is_detected_under_the_root_read_at_each_call(
        v2_root: Path, v1_root: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert hierarchy(v2_root) == "v2"
    assert hierarchy(v1_root) == "v1"
    monkeypatch.setenv("AUTOGRADER_CGROUP_ROOT", str(v2_root))
    assert cgroup_root() == v2_root
    monkeypatch.delenv("AUTOGRADER_CGROUP_ROOT")
    assert cgroup_root() == Path("/sys/fs/cgroup")


def test_v2_enables_pids_memory_and_cpu_and_sets_the_leaf_limits(v2_root: Path) -> None:
    group = Cgroup("run-a", LIMITS)
    leaf = v2_root / "autograder" / "run-a"
    assert group.paths == [leaf]
    assert group.version == "v2"
    assert group.controllers == {"pids", "memory", "cpu"}
    enabled = "+pids +memory +cpu"
    assert (v2_root / "cgroup.subtree_control").read_text() == enabled
    assert (v2_root / "autograder" / "cgroup.subtree_control").read_text() == enabled
    assert (leaf / "pids.max").read_text() == "32"
    assert (leaf / "memory.max").read_text() == MEMORY_BYTES
    assert (leaf / "cpu.weight").read_text() == "100"  # a share of its own, the default
    assert not (leaf / "memory.limit_in_bytes").exists()
    info = json.loads(json.dumps(group.info()))
    assert info == {"version": "v2", "controllers": ["cpu", "memory", "pids"],
                    "paths": [str(leaf)]}
    assert group.bounds(separate_uid=False) == {
        "cgroup": "v2", "processes": "cgroup", "memory": "cgroup", "cpu": "cgroup"}


def test_v2_leaves_an_already_enabled_subtree_control_alone(v2_root: Path) -> None:
    (v2_root / "cgroup.subtree_control").write_text("cpu memory pids\n")
    group = Cgroup("run-a", LIMITS)
    assert (v2_root / "cgroup.subtree_control").read_text() == "cpu memory pids\n"
    assert group.controllers == {"pids", "memory", "cpu"}


def test_v2_controller_the_root_does_not_offer_is_unavailable(v2_root: Path) -> None:
    (v2_root / "cgroup.controllers").write_text("io memory\n")
    group = Cgroup("run-a", LIMITS)
    leaf = v2_root / "autograder" / "run-a"
    assert group.controllers == {"memory"}
    assert (v2_root / "cgroup.subtree_control").read_text() == "+memory"
    assert (v2_root / "autograder" / "cgroup.subtree_control").read_text() == "+memory"
    assert not (leaf / "pids.max").exists()
    assert (leaf / "memory.max").read_text() == MEMORY_BYTES
    assert group.bounds(separate_uid=False)["processes"] is None
    assert group.bounds(separate_uid=True) == {
        "cgroup": "v2", "processes": "rlimit", "memory": "cgroup", "cpu": None}


def test_v2_refused_subtree_control_keeps_the_leaf_without_limits(v2_root: Path) -> None:
    # A directory in the file's place refuses every write, as EBUSY would.
    (v2_root / "autograder" / "cgroup.subtree_control").mkdir(parents=True)
    group = Cgroup("run-a", LIMITS)
    leaf = v2_root / "autograder" / "run-a"
    assert group.paths == [leaf] and group.available
    assert group.controllers == set()
    assert not (leaf / "pids.max").exists() and not (leaf / "memory.max").exists()
    assert group.bounds(separate_uid=True) == {
        "cgroup": "v2", "processes": "rlimit", "memory": "rlimit", "cpu": None}


def test_v2_a_refused_controller_does_not_cost_the_other(
        v2_root: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    write = cgroups.write_control

    def refuse_memory(path: Path, value: str) -> None:
        if path.name == "cgroup.subtree_control" and "memory" in value:
            raise OSError(errno.EBUSY, "Device or resource busy")
        write(path, value)

    monkeypatch.setattr(cgroups, "write_control", refuse_memory)
    group = Cgroup("run-a", LIMITS)
    leaf = v2_root / "autograder" / "run-a"
    assert group.controllers == {"pids", "cpu"}
    # (the fake file keeps only the last of the one-at-a-time writes)
    assert "memory" not in (v2_root / "cgroup.subtree_control").read_text()
    assert (leaf / "pids.max").read_text() == "32"
    assert not (leaf / "memory.max").exists()


def test_v2_nothing_writable_creates_nothing(v2_root: Path) -> None:
    (v2_root / "autograder").write_text("")  # mkdir fails, as on a folder not ours
    group = Cgroup("run-a", LIMITS)
    assert not group.available and group.version is None
    assert (v2_root / "cgroup.subtree_control").read_text() == ""
    assert group.bounds(separate_uid=False) == {
        "cgroup": None, "processes": None, "memory": "rlimit", "cpu": None}


def test_v2_kill_all_writes_cgroup_kill_and_kills_the_members(
        v2_root: Path, children: list[subprocess.Popen[bytes]]) -> None:
    leaf = _kernel_leaf(v2_root, "run-a")
    group = Cgroup("run-a", LIMITS)
    child = _join(group, children)
    assert group.kill_all()
    assert (leaf / "cgroup.kill").read_text() == "1"
    _assert_killed(child)


def test_v2_without_cgroup_kill_the_loop_still_kills(
        v2_root: Path, children: list[subprocess.Popen[bytes]]) -> None:
    leaf = _kernel_leaf(v2_root, "run-a")
    (leaf / "cgroup.kill").unlink()  # a kernel older than 5.14
    group = Cgroup("run-a", LIMITS)
    child = _join(group, children)
    assert group.kill_all()
    assert not (leaf / "cgroup.kill").exists()
    _assert_killed(child)


def test_v2_existing_knows_its_version_and_reaps(
        v2_root: Path, children: list[subprocess.Popen[bytes]]) -> None:
    leaf = _kernel_leaf(v2_root, "run-a")
    child = _join(Cgroup("run-a", LIMITS), children)
    group = Cgroup.existing([str(leaf)])
    assert group.version == "v2"
    assert group.controllers == {"pids", "memory", "cpu"}
    assert group.kill_all()
    assert (leaf / "cgroup.kill").read_text() == "1"
    _assert_killed(child)


def test_v2_remove_takes_the_leaf_and_keeps_the_parent(v2_root: Path) -> None:
    (v2_root / "cgroup.controllers").write_text("")  # an empty leaf, as rmdir needs here
    group = Cgroup("run-a", LIMITS)
    assert group.paths[0].is_dir()
    group.remove()
    assert not group.paths[0].exists()
    assert (v2_root / "autograder").is_dir()


def test_v1_fake_tree_still_works(
        v1_root: Path, children: list[subprocess.Popen[bytes]]) -> None:
    group = Cgroup("run-a", LIMITS)
    pids, memory = v1_root / "pids/autograder/run-a", v1_root / "memory/autograder/run-a"
    assert group.paths == [pids, memory]
    assert group.version == "v1" and group.controllers == {"pids", "memory"}
    assert (pids / "pids.max").read_text() == "32"
    assert (memory / "memory.limit_in_bytes").read_text() == MEMORY_BYTES
    assert not (memory / "memory.max").exists()
    again = Cgroup.existing(map(str, group.paths))
    assert again.version == "v1" and again.controllers == {"pids", "memory"}
    child = _join(group, children)
    assert again.kill_all()
    _assert_killed(child)


def test_v1_unmounted_controller_is_not_created(v1_root: Path) -> None:
    (v1_root / "memory").rmdir()
    group = Cgroup("run-a", LIMITS)
    assert group.controllers == {"pids"}
    assert not (v1_root / "memory").exists()
    assert group.bounds(separate_uid=False) == {
        "cgroup": "v1", "processes": "cgroup", "memory": "rlimit", "cpu": None}


def test_v1_cpu_group_sits_at_the_top_of_its_hierarchy(v1_root: Path) -> None:
    """A share of its own beside the grader's processes, not one shared by all students."""
    (v1_root / "cpu").mkdir()
    group = Cgroup("run-a", LIMITS)
    cpu = v1_root / "cpu" / "autograder-run-a"
    assert cpu in group.paths and group.controllers == {"pids", "memory", "cpu"}
    assert (cpu / "cpu.shares").read_text() == "1024"
    assert not (v1_root / "cpu" / "autograder").exists()
    assert Cgroup.existing(map(str, group.paths)).controllers == {"pids", "memory", "cpu"}
    assert group.bounds(separate_uid=True)["cpu"] == "cgroup"


@pytest.mark.parametrize(("info", "separate_uid", "expected"), [
    (None, True, {"cgroup": None, "processes": "rlimit", "memory": "rlimit", "cpu": None}),
    (None, False, {"cgroup": None, "processes": None, "memory": "rlimit", "cpu": None}),
    ({"version": None, "controllers": [], "paths": []}, False,
     {"cgroup": None, "processes": None, "memory": "rlimit", "cpu": None}),
    ({"version": "v2", "controllers": ["cpu", "memory", "pids"], "paths": ["/x"]}, True,
     {"cgroup": "v2", "processes": "cgroup", "memory": "cgroup", "cpu": "cgroup"}),
    ({"version": "v1", "controllers": ["memory"], "paths": ["/x"]}, True,
     {"cgroup": "v1", "processes": "rlimit", "memory": "cgroup", "cpu": None}),
    ({"version": "v2", "controllers": [], "paths": ["/x"]}, False,
     {"cgroup": "v2", "processes": None, "memory": "rlimit", "cpu": None}),
])
def test_describe_bounds(info: dict[str, object] | None, separate_uid: bool,
                         expected: dict[str, str | None]) -> None:
    described = describe_bounds(info, separate_uid)
    assert described == expected
    assert json.loads(json.dumps(described)) == expected


def _machine_v1_writable() -> bool:
    root = Path("/sys/fs/cgroup")
    return (os.geteuid() == 0 and not (root / "cgroup.controllers").exists()
            and os.access(root / "pids", os.W_OK))


@pytest.mark.skipif(not _machine_v1_writable(), reason="needs root on a v1 machine")
def test_machine_v1_group_is_created_killed_and_removed(
        monkeypatch: pytest.MonkeyPatch, children: list[subprocess.Popen[bytes]]) -> None:
    monkeypatch.delenv("AUTOGRADER_CGROUP_ROOT", raising=False)
    group = Cgroup(f"test-{uuid.uuid4().hex[:8]}", Limits(processes=16, memory_mb=256))
    try:
        assert group.version == "v1" and "pids" in group.controllers
        pids = Path("/sys/fs/cgroup/pids/autograder") / group.paths[0].name
        assert (pids / "pids.max").read_text().strip() == "16"
        child = _join(group, children)
        assert group.kill_all()
        _assert_killed(child)
    finally:
        group.remove()
    assert not any(p.exists() for p in group.paths)
