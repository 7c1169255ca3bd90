"""Processes a grading run left behind: there must be none."""

from __future__ import annotations

from pathlib import Path

from autograder.core.results import RunResult


def leftovers(result: RunResult) -> list[int]:
    """Live processes in the run's process groups or cgroups, or owned by its student user."""
    started = result.processes
    groups = {p.pid for p in started}
    cgroups = {Path(c).name for p in started for c in p.cgroups}
    uid = result.student_uid
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            membership = (entry / "cgroup").read_text()
            owner = entry.stat().st_uid
        except OSError:
            continue
        fields = stat.rsplit(")", 1)[1].split()
        if fields[0] == "Z":
            continue  # dead, waiting to be reaped: nothing runs
        if int(fields[2]) in groups or any(f"/{name}\n" in membership for name in cgroups) \
                or (uid is not None and owner == uid):
            found.append(int(entry.name))
    return found
