"""Test modules run in several child pytests at once, and their reports merged into one.

A grading's test modules each build a world and probe of their own, so they can run at
the same time in separate children, each child on a ROS domain of its own: the grading
then takes about as long as its slowest module instead of the sum.  The functions here
are pure: which modules a grading has (in the order pytest collects them), how they are
shared out among children, and the children's raw reports merged as if one child had
run them all.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any, Literal

from autograder.core.report import RawReport, RawTest

ModuleJobs = int | Literal["auto"]


def find_modules(folders: Iterable[Path]) -> list[Path]:
    """The test modules in ``folders``, in pytest's collection order: folder by folder as
    given, then by path inside each (``test_*.py`` and ``*_test.py``)."""
    found: list[Path] = []
    for folder in folders:
        files = {p for pattern in ("test_*.py", "*_test.py") for p in folder.rglob(pattern)
                 if p.is_file()}
        found.extend(sorted(files, key=lambda p: p.relative_to(folder).parts))
    return found


def children_for(requested: ModuleJobs, modules: int, cores: float) -> int:
    """How many children a grading of ``modules`` test modules runs: ``auto`` is one per
    module as far as the cores go; never more children than modules, never fewer than one."""
    wanted = max(1, math.floor(cores)) if requested == "auto" else int(requested)
    return max(1, min(wanted, modules))


def share_out(modules: Sequence[Path], children: int) -> list[list[Path]]:
    """``modules`` shared out among ``children`` groups, round-robin in collection order
    (neighbouring modules, often of similar length, go to different children). Modules of
    the same file name stay in one group: their bags (``--record``) are named after it."""
    groups: list[list[Path]] = [[] for _ in range(max(1, children))]
    by_stem: dict[str, int] = {}
    turn = 0
    for module in modules:
        if module.stem not in by_stem:
            by_stem[module.stem] = turn % len(groups)
            turn += 1
        groups[by_stem[module.stem]].append(module)
    return [g for g in groups if g]


def module_of(nodeid: str) -> str:
    """The test module's path in a node id ("tests/public/test_a.py::test_b" ->
    "tests/public/test_a.py")."""
    return nodeid.partition("::")[0]


def merge(reports: Sequence[RawReport], order: Sequence[str]) -> RawReport:
    """The children's reports as one, as a single child would have written it.

    Tests follow ``order`` (the modules' node-id paths in collection order; a module not in
    it goes last), each module's tests in its child's order.  Any forged report forges the
    whole.  ``data``: per-module and per-test entries are joined (they are disjoint),
    lists concatenated, ``first_test_at`` is the earliest, and peak ``memory`` is summed
    over the children (they run at once: an upper bound of the grading's peak)."""
    if any(r.forged for r in reports):
        return RawReport(forged=True)
    # One child's tests are already as pytest collected them.
    rank = {module: i for i, module in enumerate(order)} if len(reports) > 1 else {}
    tests: list[tuple[int, int, RawTest]] = []
    for report in reports:
        for position, test in enumerate(report.tests):
            tests.append((rank.get(module_of(test.nodeid), len(rank)), position, test))
    tests.sort(key=lambda entry: (entry[0], entry[1]))
    return RawReport(tests=[t for _, _, t in tests],
                     data=merge_data([r.data for r in reports]),
                     output_log="\n\n".join(r.output_log for r in reports if r.output_log))


_DICTS = ("logs", "recordings", "pacing", "bags", "timing", "sim_seconds")
_LISTS = ("log_files", "processes", "startup_seconds", "warnings")


def merge_data(datas: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """The children's report ``data`` as one (see :func:`merge`)."""
    merged: dict[str, Any] = {}
    for key in _DICTS:
        parts = [d[key] for d in datas if key in d]
        if parts:
            merged[key] = {k: v for part in parts for k, v in part.items()}
    for key in _LISTS:
        parts = [d[key] for d in datas if key in d]
        if parts:
            merged[key] = [item for part in parts for item in part]
    starts = [d["first_test_at"] for d in datas if d.get("first_test_at") is not None]
    if starts:
        merged["first_test_at"] = min(starts)
    counted = [d["not_run"] for d in datas if "not_run" in d]
    if counted:  # only one child counts the tests it does not run
        merged["not_run"] = counted[0]
    memories = [d["memory"] for d in datas if d.get("memory")]
    if memories:
        merged["memory"] = {name: round(sum(m.get(name, 0.0) for m in memories), 1)
                            for name in ("grader_mb", "student_mb", "total_mb")}
    for data in datas:  # anything else: the first child's
        for key, value in data.items():
            merged.setdefault(key, value)
    return merged
