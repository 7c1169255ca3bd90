"""Where a grading's wall seconds go, per test module (the results file's ``timing``).

Each test module's wall time (its tests' setup, call and teardown) is split into:

* ``world_start``: starting and stopping the simulated world and the grader's probe;
* ``node_start``: from launching the student's program to its node being on the graph;
* ``sim_wait``: tests blocked waiting on simulation time (``SimBridge.wait_until`` and
  ``wait_for``), less ``busy_hold``;
* ``busy_hold``: of those waits, the wall seconds the world held a tick past its deadline
  for a student process that had work (see :mod:`sim.pacing`);
* ``checks``: the rest, the tests' own work (``total`` less the others).

Waits inside a node start count as node start only. Measuring costs a clock read and a
lock per wait; nothing here changes what a test sees.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Iterator

PHASES = ("world_start", "node_start", "sim_wait", "busy_hold")


class Timing:
    """Thread-safe wall-second sums per test module and phase."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._sums: dict[str, dict[str, float]] = {}
        self._inside = threading.local()  # the phase this thread is timing as a whole

    def add(self, module: str, phase: str, seconds: float) -> None:
        """Add ``seconds`` (negative counts as 0) to ``module``'s ``phase``."""
        with self._lock:
            sums = self._sums.setdefault(module, dict.fromkeys((*PHASES, "total"), 0.0))
            sums[phase] = sums.get(phase, 0.0) + max(0.0, seconds)

    @contextlib.contextmanager
    def phase(self, module: str, phase: str) -> Iterator[None]:
        """Time the block as ``phase`` of ``module``; waits in it count as this phase only
        (nested phases too)."""
        if getattr(self._inside, "phase", None) is not None:
            yield
            return
        self._inside.phase = phase
        began = time.monotonic()
        try:
            yield
        finally:
            self._inside.phase = None
            self.add(module, phase, time.monotonic() - began)

    def waited(self, module: str, seconds: float, held: float) -> None:
        """A wait on simulation time of ``seconds``, ``held`` of them by a busy student
        process; ignored inside a timed phase (a node start's wait is its own)."""
        if getattr(self._inside, "phase", None) is not None:
            return
        held = min(max(0.0, held), max(0.0, seconds))
        self.add(module, "busy_hold", held)
        self.add(module, "sim_wait", seconds - held)

    def to_dict(self) -> dict[str, dict[str, float]]:
        """``{module: {world_start, node_start, sim_wait, busy_hold, checks, total}}`` in
        seconds rounded to ms; ``checks`` is ``total`` less the others, at least 0."""
        with self._lock:
            sums = {module: dict(phases) for module, phases in self._sums.items()}
        out: dict[str, dict[str, float]] = {}
        for module, phases in sums.items():
            spent = sum(phases[p] for p in PHASES)
            row = {p: round(phases[p], 3) for p in PHASES}
            row["checks"] = round(max(0.0, phases["total"] - spent), 3)
            row["total"] = round(phases["total"], 3)
            out[module] = row
        return out


def module_of(nodeid: str) -> str:
    """The test module a node id belongs to (``tests/test_x.py::test_y`` gives
    ``tests/test_x.py``)."""
    return nodeid.split("::", 1)[0]
