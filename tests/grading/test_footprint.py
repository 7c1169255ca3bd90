"""A grading's memory as its process tree's summed PSS (autograder.grading.footprint): the
parsing and summing over a fake /proc, and one sample of a real process tree."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from autograder.grading.footprint import (
    Footprint,
    process_kb,
    pss_kb,
    resident_kb,
    tree_kb,
)
from sim.procstate import child_pids, descendants

ROLLUP = """\
55d1c1e4f000-7ffd6a1b6000 ---p 00000000 00:00 0                          [rollup]
Rss:               95056 kB
Pss:               41234 kB
Pss_Dirty:         30112 kB
Pss_Anon:          30000 kB
Pss_File:          11234 kB
Pss_Shmem:             0 kB
Shared_Clean:      60000 kB
Anonymous:         30000 kB
"""


def test_pss_is_read_from_its_own_line_of_smaps_rollup() -> None:
    assert pss_kb(ROLLUP) == 41234
    # Pss_Anon and friends are parts, not the whole; a zombie's rollup is empty.
    assert pss_kb("Pss_Anon:  100 kB\nPss_File:  20 kB\n") is None
    assert pss_kb("") is None


def test_resident_size_is_statm_second_field_in_pages() -> None:
    assert resident_kb("340000 23764 9000 1 0 40000 0\n", 4) == 95056
    assert resident_kb("0 0 0 0 0 0 0\n", 4) == 0  # a zombie
    assert resident_kb("", 4) is None


def test_children_files_list_pids_separated_by_spaces() -> None:
    assert child_pids("15456 15460 \n") == [15456, 15460]
    assert child_pids("") == []


def _process(proc: Path, pid: int, *, pss: int | None = None, rss_pages: int = 0,
             threads: dict[int, list[int]] | None = None) -> None:
    """A fake /proc/PID: a rollup saying ``pss`` (none: no rollup, as for a process the
    sampler may not read), statm with ``rss_pages``, and each thread's children."""
    folder = proc / str(pid)
    folder.mkdir(parents=True)
    if pss is not None:
        (folder / "smaps_rollup").write_text(ROLLUP.replace("41234", str(pss)))
    (folder / "statm").write_text(f"90000 {rss_pages} 100 1 0 500 0\n")
    for tid, children in (threads or {pid: []}).items():
        (folder / "task" / str(tid)).mkdir(parents=True)
        (folder / "task" / str(tid) / "children").write_text(
            "".join(f"{child} " for child in children))


@pytest.fixture
def proc(tmp_path: Path) -> Path:
    """A grading's tree: the grader 10 (whose other child 11 is another grading's), the
    child pytest 20 whose second thread started the student 30, who started 40 (not
    readable: counted by its resident size) and 50 (ended since, listed still)."""
    _process(tmp_path, 10, pss=30_000, threads={10: [11, 20]})
    _process(tmp_path, 11, pss=70_000)
    _process(tmp_path, 20, pss=60_000, threads={20: [], 21: [30], 22: []})
    _process(tmp_path, 30, pss=40_000, threads={30: [40, 50]})
    _process(tmp_path, 40, rss_pages=1000)
    _process(tmp_path, 99, pss=1_000_000)  # nobody's
    return tmp_path


def test_descendants_come_from_every_threads_children(proc: Path) -> None:
    assert sorted(descendants(20, proc)) == [30, 40, 50]
    assert descendants(50, proc) == []  # ended: nothing below it


def test_an_unreadable_process_counts_its_resident_size_and_an_ended_one_nothing(
        proc: Path) -> None:
    assert process_kb(30, proc, page_kb=4) == 40_000
    assert process_kb(40, proc, page_kb=4) == 4000
    assert process_kb(50, proc, page_kb=4) == 0


def test_the_tree_is_the_grader_alone_and_each_child_with_its_descendants(proc: Path) -> None:
    # 10 + 20 + 30 + 40 (statm) + 50 (gone); not 11 (another grading's), not 99.
    assert tree_kb(10, [20], proc, page_kb=4) == 30_000 + 60_000 + 40_000 + 4000
    # A process reached twice counts once.
    assert tree_kb(10, [20, 30], proc, page_kb=4) == 134_000
    assert tree_kb(10, [], proc, page_kb=4) == 30_000


def test_the_template_counts_alone_and_once(proc: Path) -> None:
    """The template the child pytests were forked from (12 here) counts by itself, not
    its other children (other gradings'), and once if it is reached twice."""
    _process(proc, 12, pss=5_000, threads={12: [99]})
    assert tree_kb(10, [20], proc, page_kb=4, alone=[12]) == 134_000 + 5_000
    assert tree_kb(10, [20], proc, page_kb=4, alone=[12, 10, 20]) == 139_000


def test_the_footprint_keeps_the_peak_sampling_at_most_every_interval(proc: Path) -> None:
    footprint = Footprint([20], interval=0.5, proc=proc, own=10)
    assert footprint.peak_mb is None
    footprint.sample(now=100.0)
    first = footprint.peak_kb
    (proc / "30" / "smaps_rollup").write_text(ROLLUP.replace("41234", "140000"))
    footprint.sample(now=100.25)  # too soon: not read
    assert (footprint.samples, footprint.peak_kb) == (1, first)
    footprint.sample(now=100.5)
    assert (footprint.samples, footprint.peak_kb) == (2, first + 100_000)
    (proc / "30" / "smaps_rollup").write_text(ROLLUP.replace("41234", "10"))
    footprint.sample(now=101.0)  # lower now: the peak stays
    assert (footprint.samples, footprint.peak_kb) == (3, first + 100_000)
    assert footprint.peak_mb == round((first + 100_000) / 1024, 1)


def test_a_real_tree_is_found_and_summed() -> None:
    """A python parent with a sleeping child: both are found below the parent, each has a
    PSS, and the sum over the tree is more than this process's alone."""
    code = ("import subprocess, sys, time\n"
            "child = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(60)'])\n"
            "print(child.pid, flush=True)\n"
            "child.wait()\n")
    parent = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    child = None
    try:
        assert parent.stdout is not None
        child = int(parent.stdout.readline())  # started: listed by the parent's thread
        assert descendants(parent.pid) == [child]
        assert process_kb(parent.pid) > 0 and process_kb(child) > 0
        alone = tree_kb(os.getpid(), [])
        assert alone > 0
        footprint = Footprint([parent.pid])
        footprint.sample()
        assert footprint.samples == 1
        assert footprint.peak_kb == pytest.approx(
            alone + process_kb(parent.pid) + process_kb(child), rel=0.2)
        assert footprint.peak_mb is not None and footprint.peak_mb > 0
    finally:
        if child is not None:
            with contextlib.suppress(ProcessLookupError):
                os.kill(child, signal.SIGKILL)
        parent.kill()
        parent.wait()


@pytest.mark.skipif(os.geteuid() != 0, reason="needs root, to sample as another user")
def test_another_users_process_counts_its_resident_size() -> None:
    """Sampled by a user who may not read its rollup (``nobody``), this process counts its
    resident size from statm, which anyone may read: more than its PSS, never nothing."""
    code = ("import os, sys\n"
            "from autograder.grading.footprint import process_kb, resident_kb\n"
            "pid = int(sys.argv[1])\n"
            "try:\n"
            "    unreadable = not open(f'/proc/{pid}/smaps_rollup').read()\n"
            "except OSError:\n"
            "    unreadable = True\n"
            "with open(f'/proc/{pid}/statm') as statm:\n"
            "    resident = resident_kb(statm.read(), os.sysconf('SC_PAGE_SIZE') // 1024)\n"
            "print(unreadable, process_kb(pid), resident)\n")
    root = Path(__file__).resolve().parents[2]
    out = subprocess.run([sys.executable, "-c", code, str(os.getpid())], cwd=root,
                         env={**os.environ, "PYTHONPATH": str(root)}, user=65534,
                         group=65534, extra_groups=[], capture_output=True, text=True,
                         check=True).stdout.split()
    unreadable, counted, resident = out[0] == "True", int(out[1]), int(out[2])
    assert unreadable
    assert counted > 0 and counted == pytest.approx(resident, rel=0.05)
    assert counted >= process_kb(os.getpid()) * 0.95  # resident is at least the PSS
