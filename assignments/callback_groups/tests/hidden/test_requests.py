"""Hidden tests: invalid readings, concurrent requests, a scan newer than the request, no
scan at all, and a node still alive at the end."""

import pytest
from helpers import (
    ANSWER_WITHIN,
    RATE_HIGH,
    RATE_LOW,
    Answer,
    Requests,
    ask,
    deadlock_hint,
    judge,
    rate_reports,
    require_alive,
    require_service,
    scan_after,
    wait_student_idle,
)

from autograder.core.errors import StudentFailure
from autograder.i18n import _, ngettext
from sim.worldfile import Box, Fault

BOX_AHEAD = Box(center=(3.45, 3.0), size=(0.1, 0.6))
CONCURRENT = 5
# With the world paused, how long (wall) an answer from an old scan is waited for.
PAUSED_WALL = 0.5
# Sim seconds test_never_deadlocks lets pass before it reads the rate reports.
SETTLE = 1.5
# test_no_fresh_scan: the world's pace while the request waits, and the answer's latency
# allowed (sim s): 1.0 s of ROS time, less a tick, plus a late answer.
SLOW_PACE = 0.5
WAIT_LOW, WAIT_HIGH = 0.9, 1.5


@pytest.mark.points(1)
def test_ignores_invalid_readings(student, probe, scans, world, alive):
    """Invalid readings (NaN, inf, below range_min) do not block the path"""
    require_alive(alive)
    start = probe.now
    for kind in ("nan", "inf", "neg_inf", "below_min"):
        world.inject(Fault(kind=kind, start=start, end=start + 2.0, fraction=0.15))
    try:
        probe.wait_sim(0.3)
        answer = ask(probe)
        judge(answer, scan_after(probe, scans, answer.sent),
              _("With 15 percent of the beams each NaN, +inf, -inf and below range_min"))
    finally:  # the next test starts with clean scans, whatever happened here
        probe.wait_for(lambda: probe.now > start + 2.0, 3.0)


@pytest.mark.points(2)
def test_concurrent_requests(student, probe, scans, rates, alive, evidence):
    """Five requests at once are all answered within 1.0 s, and scans keep being counted"""
    require_alive(alive)
    requests = Requests(probe)
    try:
        require_service(requests)
        start = probe.now
        answers = [requests.send() for _ in range(CONCURRENT)]
        requests.wait(answers, 3.0)
        late = [a for a in answers if a.latency is None or a.latency > ANSWER_WITHIN]
        if late:
            got = sum(1 for a in answers if a.answered is not None)
            raise StudentFailure(
                ngettext("{late} of {n} requests sent together took more than 1.0 s of "
                         "simulation time or was never answered (answered: {got} of {n}).",
                         "{late} of {n} requests sent together took more than 1.0 s of "
                         "simulation time or were never answered (answered: {got} of {n}).",
                         len(late)).format(n=CONCURRENT, got=got, late=len(late)),
                _concurrency_hint(answers))
        for answer in answers:
            judge(answer, scan_after(probe, scans, answer.sent),
                  _("Among five requests sent together"))
        probe.wait_for(lambda: probe.now > start + 2.5, 4.0)
        reports = rate_reports(rates, start + 0.5, start + 2.5)
        evidence.intervals("scans_per_second",
                           [t for t in rates.times if start <= t <= start + 2.5])
        if len(reports) < 2 or not all(RATE_LOW <= v <= RATE_HIGH for v in reports):
            raise StudentFailure(
                _("While requests were served, scans_per_second read {values}; expected "
                  "about 10 every second.").format(
                    values=", ".join(f"{v:g}" for v in reports) or _("nothing")),
                _("A waiting request must not hold up the scan callback or the rate timer: "
                  "give the service a callback group of its own."))
    finally:
        # Requests still queued in the node would delay the next test's: it starts once
        # they are answered (each waits at most 1.0 s), whatever this one found.
        requests.wait(requests.answers, CONCURRENT * ANSWER_WITHIN + 0.5)
        requests.close()


def _concurrency_hint(answers: list) -> str:
    """Answers that came one after another, each a wait later: they queued."""
    latencies = sorted(a.latency for a in answers if a.latency is not None)
    if len(latencies) == len(answers) and latencies[-1] - latencies[0] > ANSWER_WITHIN / 2:
        return _("The answers came {latencies} s after the requests: one after another, each "
                 "waiting for the one before. Give the service a ReentrantCallbackGroup of "
                 "its own (and enough executor threads), or serve each request within "
                 "0.1 s.").format(latencies=", ".join(f"{t:.2f}" for t in latencies))
    return _("While one request waits for its scan, the others must not wait for it: a "
             "ReentrantCallbackGroup for the service (and enough executor threads), or "
             "requests served one after another, each within 0.1 s.")


@pytest.mark.points(1)
def test_no_fresh_scan(student, probe, world, alive):
    """Without a scan for 3 s, check_path answers `success=false` after waiting 1.0 s"""
    require_alive(alive)
    start = probe.now
    world.inject(Fault(kind="dropout", start=start, end=start + 3.0))
    pace = world.real_time_factor
    try:
        probe.wait_sim(0.3)
        # At half pace a wait timed by the wall clock (1.0 s of it is at most 0.5 s of
        # simulation time then: the world never runs faster than its pace) is told from
        # one in ROS time, whatever the machine's load.
        world.set_real_time_factor(SLOW_PACE)
        try:
            answer = ask(probe)
        finally:
            world.set_real_time_factor(pace)
    finally:  # scans flow again before the next test
        probe.wait_for(lambda: probe.now > start + 3.3, 4.0)
    response = answer.response
    if response is None or response.success:
        raise StudentFailure(
            _("With no scan coming, check_path answered `success={got}` ({message!r}); the "
              "path cannot be confirmed clear, so success must be false.").format(
                got=getattr(response, "success", None),
                message=getattr(response, "message", "")),
            _("It answered {latency:.2f} s after the request, so from a scan older than the "
              "request: wait up to 1.0 s of ROS time for a scan that arrives after it, and "
              "answer `success=False` when none comes.").format(latency=answer.latency)
            if response is not None and answer.latency < 0.5 else
            _("Answer only from a scan that arrives after the request; when none comes "
              "within 1.0 s, say so with `success=False`."))
    # 1.0 s of ROS time is asked for, give or take a tick and a late answer.
    if not WAIT_LOW <= answer.latency <= WAIT_HIGH:
        raise StudentFailure(
            _("With no scan coming, check_path answered after {latency:.2f} s of simulation "
              "time; it must wait 1.0 s of ROS time for a scan first.").format(
                latency=answer.latency),
            _late_answer_hint(answer))


def _late_answer_hint(answer: Answer) -> str:
    """A wait timed by the wall clock, too short a wait, or a request that waited its
    turn: told apart by the answer's latency in simulation and in wall time."""
    if answer.wall_latency is not None and abs(answer.wall_latency - ANSWER_WITHIN) <= 0.3:
        return _("The answer came {wall:.2f} s of wall time after the request, but {sim:.2f} "
                 "s of simulation time: the wait was timed by the wall clock (time.sleep, "
                 "time.time, a timeout= argument). Measure it with self.get_clock().now(), "
                 "which follows /clock.").format(wall=answer.wall_latency, sim=answer.latency)
    if answer.latency < WAIT_LOW:
        return _("Measure the wait with self.get_clock().now(), which follows /clock.")
    return _("The answer came {sim:.2f} s after the request, longer than the 1.0 s wait "
             "itself: the request waited its turn before its callback ran, behind other "
             "callbacks of its callback group. Give the service a callback group of its "
             "own, and the executor a thread free for it.").format(sim=answer.latency)


@pytest.mark.points(2)
def test_answer_uses_newer_scan(student, probe, scans, world, alive):
    """The answer comes from a scan newer than the request (a box appears just before it)"""
    require_alive(alive)
    requests = Requests(probe)
    try:
        require_service(requests)
        probe.wait_sim(0.2)
        world.pause()
        try:
            # Every scan the node had is now handled; the box is in the next one only.
            wait_student_idle(student, 2.0)
            world.inject(Fault(kind="obstacle", start=world.now, box=BOX_AHEAD))
            answer = requests.send()
            world.wait_for(lambda: requests.answered([answer]), float("inf"), PAUSED_WALL)
            early = answer.answered is not None
        finally:
            world.resume()
        if early:
            raise StudentFailure(
                _("check_path answered ({message!r}) before any scan newer than the request "
                  "existed: the world was paused, and a box had just appeared ahead.").format(
                    message=getattr(answer.response, "message", "")),
                _("Wait in the service callback until the scan callback delivers a scan "
                  "that arrived after the request (a counter or a threading.Event set by "
                  "the scan callback), then answer from that one."))
        if not requests.wait([answer], 3.0):
            raise StudentFailure(
                _("check_path did not answer within 3 s of simulation time."), deadlock_hint())
        judge(answer, scan_after(probe, scans, answer.sent),
              _("With a box appearing 0.40 m ahead just before the request"))
    finally:
        requests.close()


@pytest.mark.points(1)
def test_never_deadlocks(student, probe, rates, alive, evidence):
    """After all that, the node still counts scans and answers"""
    require_alive(alive)
    # The reports of the first SETTLE s may still carry what earlier tests did (scans
    # held back by a request and counted at once when it ended); the node must count
    # steadily after that.
    start = probe.now + SETTLE
    probe.wait_for(lambda: probe.now > start + 2.2, SETTLE + 3.0)
    reports = rate_reports(rates, start + 0.1, start + 2.2)
    evidence.intervals("scans_per_second",
                       [t for t in rates.times if start <= t <= start + 2.2])
    if len(reports) < 2 or not all(RATE_LOW <= v <= RATE_HIGH for v in reports):
        raise StudentFailure(
            _("At the end, scans_per_second read {values} in 2 s of simulation time; expected "
              "about 10 every second.").format(
                values=", ".join(f"{v:g}" for v in reports) or _("nothing")),
            deadlock_hint())
    answer = ask(probe)
    # Alive, not fast: the other tests judge how long an answer took, and a wait of 1.0 s
    # answered a tick late must not decide this one.
    if answer.latency > ANSWER_WITHIN + 0.5:
        raise StudentFailure(
            _("At the end, check_path took {latency:.2f} s of simulation time.").format(
                latency=answer.latency), deadlock_hint())
