"""The raw grading report: what the pytest child writes as the run goes, and the grader
reads when it ends. Written and read here only.

The file is signed (:mod:`autograder.core.signing`) with a key the grader hands the
child over a pipe, so a student's program that can write the grader's files cannot
forge a score. Each stopped program's whole output goes to a file of its own beside the
report (``report.logs/NNN.log``), named in the report with its size and digest, so the
report, rewritten after every test, stays small.
"""

from __future__ import annotations

import dataclasses
import json
import os
import stat
from pathlib import Path
from typing import Any

from autograder.core.output_budget import digest, log_folder
from autograder.core.signing import Forged, sign, verify
from autograder.i18n import _


@dataclasses.dataclass
class RawTest:
    """One test as the child saw it: its outcome, points and what the student reads."""

    nodeid: str
    name: str
    label: str
    max_score: int | float | str
    visibility: str
    reveal: str
    done: bool = False
    status: str = "error"
    message: str = ""
    hint: str = ""
    details: str = ""
    fraction: float | None = None
    charts: list[dict[str, Any]] = dataclasses.field(default_factory=list)
    strangers: list[int] = dataclasses.field(default_factory=list)  # who disturbed it
    core: bool = False  # named in exercise.yaml's core (the live test lines mark it)


@dataclasses.dataclass
class RawReport:
    """The whole report: the tests, and what the run kept (``data``: logs, log_files,
    recordings, processes, pacing, startup_seconds)."""

    tests: list[RawTest] = dataclasses.field(default_factory=list)
    data: dict[str, Any] = dataclasses.field(default_factory=dict)
    forged: bool = False  # the signature did not match: nothing in it can be trusted
    output_log: str = ""  # every program's kept output, read from the log files

    @property
    def processes(self) -> list[dict[str, Any]]:
        return self.data.get("processes", [])


def write(path: Path, tests: list[RawTest], data: dict[str, Any], key: bytes) -> None:
    """Replace the report at ``path`` atomically (the grader reads it while it grows)."""
    payload = json.dumps({"tests": [dataclasses.asdict(t) for t in tests], "data": data},
                         default=str)
    tmp = path.with_suffix(".tmp")
    tmp.write_text(sign(payload, key))
    tmp.replace(path)


def keep_log(path: Path, data: dict[str, Any], nodeid: str, text: str) -> None:
    """Write one program's output beside the report and name it in ``data``."""
    folder = log_folder(path)
    folder.mkdir(exist_ok=True)
    name = f"{len(data['log_files']) + 1:03d}.log"
    raw = text.encode("utf-8", "replace")
    (folder / name).write_bytes(raw)
    data["log_files"].append({"test": nodeid, "file": name, "bytes": len(raw),
                              "sha256": digest(raw)})


def read(path: Path, key: bytes, with_logs: bool = False) -> RawReport:
    """The report at ``path``: empty if there is none yet, ``forged`` if someone else wrote
    it; ``with_logs`` also reads the programs' output files it vouches for."""
    try:
        text = path.read_text()
    except OSError:
        return RawReport()
    try:
        raw = verify(text, key)
    except Forged:
        return RawReport(forged=True)
    fields = {f.name for f in dataclasses.fields(RawTest)}
    report = RawReport(tests=[RawTest(**{k: v for k, v in t.items() if k in fields})
                              for t in raw.get("tests", [])], data=raw.get("data", {}))
    if with_logs:
        report.output_log = output_log(report.data, path)
    return report


def output_log(data: dict[str, Any], path: Path) -> str:
    """Every program's kept output, from the files the signed report names (read before
    the run's folder goes); a file that is not the one vouched for is left out."""
    parts = [f"==> {entry['test']} <==\n{_read_log(log_folder(path), entry)}"
             for entry in data.get("log_files", [])]
    return "\n\n".join(parts)


def _read_log(folder: Path, entry: dict[str, Any]) -> str:
    """One program's kept output, if the file is the one the report vouches for."""
    path = folder / Path(entry["file"]).name
    raw = b""
    try:  # not through a link, never blocking on a FIFO, and the size before the read
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        fd = None
    if fd is not None:
        with os.fdopen(fd, "rb") as fh:
            found = os.fstat(fh.fileno())
            if stat.S_ISREG(found.st_mode) and found.st_size == entry["bytes"]:
                raw = fh.read(entry["bytes"])
    if digest(raw) != entry["sha256"]:
        return _("(This output was changed after your program ran, so it is left out.)")
    return raw.decode("utf-8", "replace")
