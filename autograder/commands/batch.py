"""Grade a folder of submissions: in parallel, resumable, sharded, into a gradebook.

Each student's results are written to ``OUT/<student>/results.json`` (and a report) as
soon as they are graded, atomically; running the batch again skips every student whose
results are there, so a crash halfway loses nothing already graded.  ``--shard I/N``
grades a stable share: a student's shard is a hash of their name, so it never moves when
others are added.  Parallel gradings each hold their own ROS domain: no cross-talk.
``jobs`` may be a chooser (``--jobs auto``): the first student is graded alone, and as
each grading ends the chooser picks the concurrency for the rest from what the gradings so
far showed (:mod:`autograder.grading.capacity`).
"""

from __future__ import annotations

import hashlib
import json
import threading
import time
from collections import deque
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from pathlib import Path

from autograder.commands import gradebook
from autograder.core.files import write_atomically
from autograder.core.results import RunResult

# Told of each grading as it ends (its wall seconds, its results, how many ran at once
# then, itself included, and how many students are left, running or not), the
# concurrency for the rest.
Chooser = Callable[[float, RunResult, int, int], int]


def students(folder: Path, suffix: str | None = None) -> dict[str, Path]:
    """One entry per student: a sub-folder, or a file (named after its stem)."""
    found: dict[str, Path] = {}
    for entry in sorted(folder.iterdir()):
        if entry.name.startswith("."):
            continue
        if entry.is_dir():
            found[entry.name] = entry
        elif entry.is_file() and (suffix is None or entry.suffix == suffix):
            found[entry.stem] = entry
    return found


def in_shard(student: str, shard: tuple[int, int] | None) -> bool:
    if shard is None:
        return True
    index, count = shard
    digest = int(hashlib.sha256(student.encode()).hexdigest()[:8], 16)
    return digest % count == index - 1


def parse_shard(text: str) -> tuple[int, int]:
    index, _, count = text.partition("/")
    i, n = int(index), int(count)
    if not 1 <= i <= n:
        raise ValueError(text)
    return i, n


def _results_path(out: Path, student: str) -> Path:
    return out / student / "results.json"


def _save(out: Path, student: str, result: RunResult,
          extra: Callable[[RunResult, Path], None] | None) -> None:
    folder = out / student
    folder.mkdir(parents=True, exist_ok=True)
    if extra is not None:
        extra(result, folder)
    # Last: its presence means this student is done.
    write_atomically(_results_path(out, student),
                     json.dumps(result.to_dict(), ensure_ascii=False, indent=2) + "\n")


def run_batch(entries: dict[str, Path], grade_one: Callable[[Path], RunResult], out: Path,
              csv_path: Path, *, jobs: int | Chooser = 1, shard: tuple[int, int] | None = None,
              extra: Callable[[RunResult, Path], None] | None = None,
              progress: Callable[[str, RunResult | None], None] | None = None,
              ) -> list[gradebook.Row]:
    """Grade every entry in this shard that has no results yet; write the gradebook.

    With a chooser for ``jobs``, the first student to grade is graded alone, and the
    chooser sets the concurrency again each time a grading ends (never above
    :func:`~autograder.grading.capacity.max_jobs` of the machine's cores). The pool
    makes its threads as gradings are started, so one as large as the queue holds only
    as many as ran at once."""
    mine = {s: p for s, p in entries.items() if in_shard(s, shard)}
    todo = {s: p for s, p in mine.items() if not _results_path(out, s).exists()}
    lock = threading.Lock()

    def work(student: str, path: Path) -> tuple[RunResult, float]:
        began = time.monotonic()
        result = grade_one(path)
        wall = time.monotonic() - began
        _save(out, student, result, extra)
        with lock:
            _write_gradebook(out, mine, csv_path)
            if progress:
                progress(student, result)
        return result, wall

    for student in sorted(set(mine) - set(todo)):
        if progress:
            progress(student, None)
    queue = deque(sorted(todo.items()))
    chooser = jobs if callable(jobs) else None
    limit = 1 if chooser is not None else max(1, int(jobs))  # type: ignore[arg-type]
    running: set[Future[tuple[RunResult, float]]] = set()
    workers = len(queue) if chooser is not None else limit
    started = getattr(chooser, "started", None)  # told of each start, where it listens
    with ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
        while queue or running:
            while queue and len(running) < limit:
                if started is not None:
                    started()
                running.add(pool.submit(work, *queue.popleft()))
            done, _pending = wait(running, return_when=FIRST_COMPLETED)
            at_once = len(running)
            running -= done
            for future in done:
                result, wall = future.result()
                if chooser is not None and queue:
                    limit = max(1, min(workers, chooser(wall, result, at_once,
                                                        len(queue) + len(running))))
    return _write_gradebook(out, mine, csv_path)


def _write_gradebook(out: Path, mine: dict[str, Path], csv_path: Path) -> list[gradebook.Row]:
    """Rows of every graded student of this batch, merged into the CSV already there."""
    rows = []
    for student in sorted(mine):
        path = _results_path(out, student)
        if path.exists():
            result = RunResult.from_dict(json.loads(path.read_text(encoding="utf-8")))
            rows.append(gradebook.row_for(student, result))
    existing = gradebook.read(csv_path) if csv_path.exists() else []
    merged = gradebook.merge(existing, rows)
    gradebook.write(csv_path, merged)
    return merged
