"""Public tests: the node starts, counts scans, and answers check_path in open space and
facing a box."""

import pytest
from helpers import (
    ANSWER_WITHIN,
    RATE_HIGH,
    RATE_LOW,
    Requests,
    ask,
    first_scan_after,
    judge,
    nearest_ahead,
    require_alive,
    require_service,
    scan_after,
)

from autograder.core.errors import GraderError, StudentFailure
from autograder.i18n import _, ngettext
from sim.worldfile import Box, Fault

# A box whose near face is 0.40 m ahead of the robot: inside 0.5 m, outside 0.3 m.
BOX_AHEAD = Box(center=(3.45, 3.0), size=(0.1, 0.6))


@pytest.mark.points(1)
def test_node_starts(student, probe, scans, rates):
    """The node starts as safety_supervisor with a check_path service and scans_per_second"""
    requests = Requests(probe)
    try:
        require_service(requests)
    finally:
        requests.close()
    if not probe.wait_for(lambda: len(rates) > 0, 3.0):
        raise StudentFailure(
            _("Nothing came on scans_per_second within 3 s of simulation time."),
            _("Nothing publishes on scans_per_second: create a publisher, "
              "`self.create_publisher(Float32, 'scans_per_second', 10)`, and publish the "
              "count from a 1 s timer.") if rates.publisher_count() == 0 else
            _("Publish a std_msgs/Float32 on scans_per_second from a 1 s timer, and spin "
              "the node: a MultiThreadedExecutor, not Jazzy's experimental EventsExecutor, "
              "which ignores callback groups and, measured here, never ran a callback."))


@pytest.mark.points(1)
def test_scan_rate(student, probe, scans, rates, alive, evidence):
    """scans_per_second reports about 10 scans per second"""
    require_alive(alive)
    start = probe.now
    probe.wait_for(lambda: sum(1 for t in rates.times if t > start) >= 4, 6.0)
    came = [m.data for t, m in rates.items if t > start]
    values = came[1:]  # the first may be partial
    evidence.intervals("scans_per_second", [t for t in rates.times if t > start])
    if len(values) < 3:
        raise StudentFailure(
            ngettext("scans_per_second came {count} time in {seconds:.1f} s of simulation "
                     "time; expected once a second.",
                     "scans_per_second came {count} times in {seconds:.1f} s of simulation "
                     "time; expected once a second.", len(came)).format(
                count=len(came), seconds=probe.now - start),
            _("Publish it from a timer with a period of 1.0 s.") if came else
            _("The node's callbacks run, yet nothing came on scans_per_second: call "
              "publish() in the 1 s timer's callback."))
    wrong = [v for v in values if not RATE_LOW <= v <= RATE_HIGH]
    if wrong:
        raise StudentFailure(
            _("scans_per_second read {values}; the world publishes 10 scans a second.")
            .format(values=", ".join(f"{v:g}" for v in values)),
            _("Count scans in the scan callback; the timer publishes the count and resets "
              "it to zero."))


@pytest.mark.points(2)
def test_open_space(student, probe, scans, alive):
    """check_path answers `success=true` with the nearest distance in open space"""
    require_alive(alive)
    answer = ask(probe)
    judge(answer, scan_after(probe, scans, answer.sent),
          _("With 2.97 m of open floor ahead and two pillars close by on the sides"))
    if answer.latency > ANSWER_WITHIN:
        raise StudentFailure(
            _("check_path took {latency:.2f} s of simulation time; a scan comes every "
              "0.1 s, so an answer is due within 1.0 s.").format(latency=answer.latency))


@pytest.mark.points(2)
def test_box_ahead(student, probe, scans, world, alive):
    """check_path answers `success=false` with the distance when a box is 0.4 m ahead"""
    require_alive(alive)
    # The scans after the time it was added at show the box; one published by a tick
    # that was under way when it was added may not.
    placed = world.inject(Fault(kind="obstacle", start=probe.now, box=BOX_AHEAD))

    def box_seen() -> bool:
        scan = first_scan_after(scans, placed)
        return scan is not None and (nearest_ahead(scan) or 9.0) < 0.5

    if not probe.wait_for(box_seen, 2.0):
        raise GraderError("the box placed 0.4 m ahead did not show in the scans")
    probe.wait_sim(0.5)  # the node has had several scans with the box by now
    answer = ask(probe)
    judge(answer, scan_after(probe, scans, answer.sent), _("Facing a box 0.40 m ahead"))
