"""The template process's own steps (autograder/grading/template.py); a child forked from it
end to end is tests/grading/test_forked.py's."""

from __future__ import annotations

import json
import os
from pathlib import Path

from autograder.grading.template import place


def test_descriptors_that_swap_numbers_each_land_where_asked(tmp_path: Path) -> None:
    """Passed descriptors whose numbers are each other's targets: moving one first must
    not overwrite the other."""
    files = [tmp_path / name for name in ("status", "log", "a", "b")]
    for path in files:
        path.write_text(path.name)
    report_read, report_write = os.pipe()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the forked test process
        try:
            opened = [os.open(path, os.O_RDONLY) for path in files]
            status = place(opened, [opened[3], opened[2]])  # a -> b's number, b -> a's
            names = [os.pread(fd, 16, 0).decode() for fd in (opened[3], opened[2], status)]
            os.write(report_write, json.dumps(names).encode())
        finally:
            os._exit(0)
    os.close(report_write)
    with os.fdopen(report_read) as report:
        names = json.loads(report.read() or "null")
    os.waitpid(pid, 0)
    assert names == ["a", "b", "status"]

