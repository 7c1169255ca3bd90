"""Shared steps of the callback_groups tests: ask check_path, judge the answer.

Requests go out through the probe's node with ``call_async`` and are not waited for one
by one, so several can be in flight at once; each answer is stamped with the sim time
the probe received it (at most a tick late, well inside the 1 s allowed).
"""

from __future__ import annotations

import math
import re
import threading
import time
from dataclasses import dataclass
from typing import Any

import pytest
from std_srvs.srv import Trigger

from autograder.core.errors import StudentFailure
from autograder.i18n import _, ngettext

SERVICE = "check_path"
SECTOR = math.radians(30.0)
CLEARANCE = 0.5
ANSWER_WITHIN = 1.0      # sim seconds a request may take (the spec's wait, at most)
DISTANCE_TOLERANCE = 0.03
RATE_LOW, RATE_HIGH = 8.0, 12.0   # scans_per_second: 10, +-1 at the second's edges
NUMBER = re.compile(r"-?\d+(?:\.\d+)?")


@dataclass
class Answer:
    sent: float
    answered: float | None = None
    response: Any = None
    # The same two moments in wall time (monotonic): how a wait was timed shows in them.
    sent_wall: float = 0.0
    answered_wall: float | None = None

    @property
    def latency(self) -> float | None:
        return None if self.answered is None else self.answered - self.sent

    @property
    def wall_latency(self) -> float | None:
        return None if self.answered_wall is None else self.answered_wall - self.sent_wall


def ahead(scan: Any) -> list[float]:
    """Every reading within +-30 degrees of straight ahead, valid or not."""
    found = []
    for i, r in enumerate(scan.ranges):
        angle = scan.angle_min + i * scan.angle_increment
        angle = math.atan2(math.sin(angle), math.cos(angle))
        if abs(angle) <= SECTOR + 1e-9:
            found.append(r)
    return found


def valid(scan: Any, r: float) -> bool:
    return math.isfinite(r) and scan.range_min <= r <= scan.range_max


def nearest_ahead(scan: Any) -> float | None:
    """The smallest valid reading within +-30 degrees of straight ahead (None: none)."""
    return min((r for r in ahead(scan) if valid(scan, r)), default=None)


def numbers(text: str) -> list[float]:
    return [float(n) for n in NUMBER.findall(text)]


class Requests:
    """check_path requests in flight from the probe's node."""

    def __init__(self, probe: Any) -> None:
        self.probe = probe
        self.client = probe.node.create_client(Trigger, SERVICE)
        self.answers: list[Answer] = []
        self._lock = threading.Lock()

    def ready(self, sim_timeout: float = 5.0) -> bool:
        return self.probe.wait_for(self.client.service_is_ready, sim_timeout)

    def send(self) -> Answer:
        answer = Answer(sent=self.probe.now, sent_wall=time.monotonic())
        future = self.client.call_async(Trigger.Request())

        def done(f: Any, a: Answer = answer) -> None:
            try:
                response = None if f.cancelled() else f.result()
            except Exception:  # a failed call is an answer that says nothing
                response = None
            with self._lock:
                a.answered = self.probe.now
                a.answered_wall = time.monotonic()
                a.response = response

        future.add_done_callback(done)
        self.answers.append(answer)
        return answer

    def answered(self, answers: list[Answer]) -> bool:
        with self._lock:
            return all(a.answered is not None for a in answers)

    def wait(self, answers: list[Answer], sim_timeout: float) -> bool:
        return self.probe.wait_for(lambda: self.answered(answers), sim_timeout)

    def close(self) -> None:
        self.probe.node.destroy_client(self.client)


def require_service(requests: Requests) -> None:
    if not requests.ready():
        raise StudentFailure(
            _("No check_path service appeared within 5 s of simulation time."),
            _("Create it with `self.create_service(Trigger, 'check_path', callback)`."))


def ask(probe: Any, sim_timeout: float = 3.0) -> Answer:
    """One request, waited for; fails the test when no answer comes."""
    requests = Requests(probe)
    try:
        require_service(requests)
        answer = requests.send()
        if not requests.wait([answer], sim_timeout):
            raise StudentFailure(
                _("check_path did not answer within {seconds:.0f} s of simulation time.")
                .format(seconds=sim_timeout), deadlock_hint())
        return answer
    finally:
        requests.close()


def require_alive(alive: bool) -> None:
    if not alive:
        pytest.skip(_("Not run: the node neither published scans_per_second nor answered "
                      "check_path, so its callbacks never run. Is it spinning, with an "
                      "executor that honours callback groups?"))


def deadlock_hint() -> str:
    """No answer at all: the request's wait held back the scan callback and /clock."""
    return _("A service callback that waits, or an async def one that awaits, holds its "
             "callback group until it returns: a scan callback or /clock subscription in "
             "the same group (the node's default group, unless you give one) cannot run, "
             "so the scan it waits for never arrives and ROS time stops for the node. Give "
             "the service a callback group of its own: with a waiting callback, spin a "
             "MultiThreadedExecutor (not Jazzy's experimental EventsExecutor, which "
             "ignores callback groups); with the README's async def design, a "
             "ReentrantCallbackGroup on the single thread is enough.")


def held_back_hint() -> str:
    """An answer after the whole wait though scans kept coming: none reached the node's
    scan callback meanwhile, so something held it back (a group shared with the
    service)."""
    return _("No scan reached the scan callback while the request waited, though the world "
             "published one every 0.1 s: the waiting service callback held it back. A "
             "MutuallyExclusiveCallbackGroup runs one of its callbacks at a time, so the "
             "service and the scan subscription must not share one: give the service a "
             "callback group of its own.")


def first_scan_after(scans: Any, stamp: float) -> Any:
    for t, scan in scans.items:
        if t > stamp + 1e-9:
            return scan
    return None


def scan_after(probe: Any, scans: Any, stamp: float) -> Any:
    """The first scan published after ``stamp``, waited for (an answer may come first)."""
    probe.wait_for(lambda: first_scan_after(scans, stamp) is not None, 1.0)
    return first_scan_after(scans, stamp)


def judge(answer: Answer, scan: Any, where: str) -> None:
    """The answer must match ``scan``: its success flag and nearest distance."""
    expected = nearest_ahead(scan) if scan is not None else None
    clear = expected is None or expected >= CLEARANCE
    response = answer.response
    if response is None:
        raise StudentFailure(_("check_path failed to answer {where}.").format(where=where))
    if scan is not None and answer.latency is not None and answer.latency >= 0.9:
        raise StudentFailure(
            _("{where}, check_path answered after {latency:.2f} s of simulation time "
              "({message!r}), though a scan came every 0.1 s.").format(
                where=where, latency=answer.latency, message=response.message),
            # Without the distance the scan held, it found no fresh scan in the whole wait.
            held_back_hint() if not _gives(response.message, expected) else
            _("Answer as soon as the first scan newer than the request arrives; the 1.0 s "
              "is the longest wait, for when no scan comes."))
    if response.success != clear:
        raise StudentFailure(
            _("{where}, check_path answered `success={got}` ({message!r}), but the nearest "
              "valid reading within 30 degrees of straight ahead was {nearest:.2f} m, so "
              "success must be {want}.").format(
                where=where, got=response.success, message=response.message,
                nearest=expected if expected is not None else float("inf"), want=clear),
            _success_hint(scan, expected, response.success))
    if expected is not None and not _gives(response.message, expected):
        raise StudentFailure(
            _("{where}, check_path's message was {message!r}; it must give the nearest "
              "distance ahead, {nearest:.2f} m.").format(
                where=where, message=response.message, nearest=expected),
            _("Put the distance in the message, e.g. f'nearest obstacle ahead: "
              "{{nearest:.2f}} m'.").format())


def _gives(message: str, distance: float | None) -> bool:
    """Whether ``message`` names ``distance`` (as an answer from that scan does)."""
    return distance is not None and any(abs(n - distance) <= DISTANCE_TOLERANCE
                                        for n in numbers(message))


def _success_hint(scan: Any, nearest: float | None, said: bool) -> str:
    """Why the success flag came out wrong, by what the scan held."""
    invalid = [r for r in ahead(scan) if not valid(scan, r)] if scan is not None else []
    if not said and invalid:
        return ngettext(
            "{count} reading ahead was invalid (NaN, +-inf, or outside `[{low}, {high}]` m): "
            "it is no obstacle. Skip a reading unless it is finite and within "
            "`[range_min, range_max]`.",
            "{count} readings ahead were invalid (NaN, +-inf, or outside `[{low}, {high}]` m): "
            "they are no obstacle. Skip a reading unless it is finite and within "
            "`[range_min, range_max]`.", len(invalid)).format(
            count=len(invalid), low=scan.range_min, high=scan.range_max)
    if said and nearest is not None:
        return _("{nearest:.2f} m ahead is under 0.5 m, yet the path was called clear: it is "
                 "clear only when every valid reading within +-30 degrees is at least 0.5 m. "
                 "Check your threshold.").format(nearest=nearest)
    return _("Use only readings that are finite and within `[range_min, range_max]`, at "
             "angles within +-30 degrees of straight ahead (wrap "
             "`angle_min + i * angle_increment` into `[-pi, pi]`); success means all of them "
             "are at least 0.5 m.")


def rate_reports(rates: Any, start: float, end: float) -> list[float]:
    return [m.data for t, m in rates.items if start <= t <= end]


def wait_student_idle(student: Any, wall_timeout: float) -> None:
    """Wait (wall time: the world is paused) until the student's process has no work."""
    from sim.procstate import process_busy

    end = time.monotonic() + wall_timeout
    while time.monotonic() < end and process_busy(student.process.pid):
        time.sleep(0.002)
