"""The CLI run as a student runs it: ``check`` or ``grade`` in a process of its own, grading
in the simulator, its output as a pipe gets it, with ``--results`` and ``--html`` files.

Several test files read the same run (what the output says, in which language, how the
report lays out code), so each run is made once per session: the ``student_runs`` fixture
(tests/conftest.py) makes the runs a module asks for two at a time, as the exercises'
proofs grade, and keeps them for the modules after it.
"""

from __future__ import annotations

import dataclasses
import json
import os
import re
import subprocess
import sys
from collections import Counter
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parent.parent
RLM = "\u200f"
TEST_LINE = re.compile(r"^ [✔✘!-] +[\d.]+/[\d.]+  (.*)$")


@dataclasses.dataclass(frozen=True)
class Spec:
    """``autograder COMMAND EXERCISE SUBMISSION --lang LANG``, run from the checkout;
    ``submission`` as the student typed it (relative to the checkout)."""

    command: str
    exercise: str
    submission: str
    lang: str


def starter(exercise: str) -> str:
    """The exercise's starter file, as a path relative to the checkout."""
    found = next((REPO / "assignments" / exercise / "starter").glob("*.py"))
    return str(found.relative_to(REPO))


class Run:
    """One command's output (stdout, as a pipe gets it), its results and its HTML report."""

    def __init__(self, stdout: str, stderr: str, code: int, results: dict[str, Any],
                 html: Path) -> None:
        self.stdout, self.stderr, self.code, self.results = stdout, stderr, code, results
        self.html = html
        # The terminal's bidi marks (a line's RLM, code's isolates) are not text.
        self.lines = [unmarked(line).removeprefix(RLM) for line in stdout.splitlines()]

    def test_lines(self) -> Counter[str]:
        return Counter(m[1] for m in map(TEST_LINE.match, self.lines) if m)

    def count(self, text: str) -> int:
        return unmarked(self.stdout).replace(RLM, "").count(text)


def unmarked(text: str) -> str:
    return text.replace("\u2066", "").replace("\u2069", "")


def env() -> dict[str, str]:
    """This environment less what would choose the language, colours or catalogs for the
    command: a student's plain terminal."""
    kept = {k: v for k, v in os.environ.items()
            if k not in ("NO_COLOR", "AUTOGRADER_LANG", "AUTOGRADER_LOCALES",
                         "AUTOGRADER_COURSE")}
    return {**kept, "PYTHONPATH": str(REPO), "TERM": "xterm-256color"}


def run(spec: Spec, folder: Path) -> Run:
    name = "-".join((spec.command, spec.exercise, Path(spec.submission).stem, spec.lang))
    results, html = folder / f"{name}.json", folder / f"report-{name}.html"
    done = subprocess.run(
        [sys.executable, "-m", "autograder.cli", spec.command, spec.exercise, spec.submission,
         "--lang", spec.lang, "--results", str(results), "--html", str(html)],
        cwd=REPO, env=env(), capture_output=True, text=True, timeout=600)
    data = json.loads(results.read_text(encoding="utf-8")) if results.exists() else {}
    return Run(done.stdout, done.stderr, done.returncode, data, html)


class StudentRuns:
    """Each run made once, two at a time; ``get`` starts every run it is asked for before
    waiting for the first."""

    def __init__(self, folder: Path, jobs: int = 2) -> None:
        self.folder = folder
        self.pool = ThreadPoolExecutor(max_workers=jobs)
        self.futures: dict[Any, Future[Any]] = {}

    def submit(self, key: Any, make: Any) -> Future[Any]:
        """``make()`` in the pool, once for ``key``."""
        if key not in self.futures:
            self.futures[key] = self.pool.submit(make)
        return self.futures[key]

    def get(self, *specs: Spec) -> list[Run]:
        futures = [self.submit(spec, lambda spec=spec: run(spec, self.folder))
                   for spec in specs]
        return [future.result() for future in futures]

    def close(self) -> None:
        self.pool.shutdown(wait=True, cancel_futures=True)
