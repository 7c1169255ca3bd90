"""The table of fault kinds: what each kind does to a scan being built (the beams it picks
read NaN, +-inf, below range_min or beyond range_max; no ranges; a length never right by
accident; nothing sent) or places in the world, the fields each reads, and that a new kind
is one entry. (Faults over time, by seed, through the injector: tests/sim/test_faults.py.)"""

from __future__ import annotations

import numpy as np
import pytest

from sim.engine import Simulation
from sim.faultkinds import KINDS, FaultKind, ScanDraft, kind_names
from sim.faults import FaultInjector
from sim.lidar import Lidar
from sim.physics import World
from sim.worldfile import Box, Circle, Fault, load_world

LIDAR = Lidar()


def _draft() -> ScanDraft:
    return ScanDraft(ranges=np.full(8, 2.0, dtype=np.float32), length=8, lidar=LIDAR)


def _pick_first_quarter(fraction: float) -> np.ndarray:
    assert fraction == 0.25  # the fault's own fraction is asked for
    return np.array([0, 1])


@pytest.mark.parametrize(("kind", "value"), [
    ("nan", np.nan), ("inf", np.inf), ("neg_inf", -np.inf),
    ("below_min", LIDAR.range_min / 2), ("above_max", LIDAR.range_max + 1.0)])
def test_a_per_beam_kind_sets_the_beams_picked(kind, value):
    scan = _draft()
    KINDS[kind].on_scan(scan, Fault(kind=kind, fraction=0.25), _pick_first_quarter)
    np.testing.assert_array_equal(scan.ranges[:2], np.float32(value))
    assert (scan.ranges[2:] == 2.0).all()
    assert (scan.length, scan.dropped) == (8, False)
    assert KINDS[kind].fields == ("start", "end", "fraction")


def test_empty_wrong_length_and_dropout():
    scan = _draft()
    KINDS["wrong_length"].on_scan(scan, Fault(kind="wrong_length", length=5), None)
    assert (scan.length, scan.beams) == (5, 8)
    scan = _draft()  # asked for the right length: one short, never right by accident
    KINDS["wrong_length"].on_scan(scan, Fault(kind="wrong_length", length=8), None)
    assert scan.length == 7
    KINDS["empty"].on_scan(scan, Fault(kind="empty"), None)
    assert scan.length == 0
    KINDS["wrong_length"].on_scan(scan, Fault(kind="wrong_length", length=5), None)
    assert scan.length == 0  # an empty scan stays empty
    assert not scan.dropped
    KINDS["dropout"].on_scan(scan, Fault(kind="dropout"), None)
    assert scan.dropped
    assert KINDS["wrong_length"].fields == ("start", "end", "length")
    assert KINDS["empty"].fields == KINDS["dropout"].fields == ("start", "end")


def test_an_obstacle_is_exactly_one_box_or_circle_placed_for_good():
    kind = KINDS["obstacle"]
    assert kind.on_scan is None and "end" not in kind.fields
    box, circle = Box(center=(1.0, 1.0), size=(0.2, 0.2)), Circle(center=(2.0, 2.0), radius=0.1)
    assert kind.places(Fault(kind="obstacle", box=box)) is box
    assert kind.places(Fault(kind="obstacle", circle=circle)) is circle
    assert kind.check(Fault(kind="obstacle", box=box)) is None
    for neither_or_both in (Fault(kind="obstacle"), Fault(kind="obstacle", box=box,
                                                          circle=circle)):
        assert kind.check(neither_or_both) == \
            "an obstacle fault needs exactly one of box or circle"


def test_every_kind_does_something_and_is_listed():
    for name, kind in KINDS.items():
        assert kind.doc and (kind.on_scan or kind.places), name
        assert set(kind.fields) <= {"start", "end", "fraction", "length", "box", "circle"}
    assert kind_names() == ("nan, inf, neg_inf, below_min, above_max, empty, wrong_length, "
                            "dropout or obstacle")


def test_a_new_kind_is_one_table_entry(tmp_path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Adding a kind to sim.faultkinds.KINDS is enough for world files and the injector."""

    def zero(scan: ScanDraft, fault: Fault, pick) -> None:
        scan.ranges[pick(fault.fraction)] = 0.0

    monkeypatch.setitem(KINDS, "zero", FaultKind("a share of beams reads 0",
                                                 ("start", "end", "fraction"), on_scan=zero))
    path = tmp_path / "zero.yaml"
    path.write_text("faults:\n  - {kind: zero, start: 0.5, fraction: 0.5}\n")
    sim = Simulation(World(load_world(path)))
    scans = [o.scan for o in (sim.step() for _ in range(200)) if o.scan is not None]
    assert not (scans[0].ranges == 0).any()  # at 0.1 s: not yet
    assert int((scans[-1].ranges == 0).sum()) == 180
    FaultInjector().add(Fault(kind="zero"))  # run-time injection knows it too
    with pytest.raises(ValueError, match="unknown fault kind"):
        FaultInjector().add(Fault(kind="gremlins"))
