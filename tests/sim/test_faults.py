"""Every fault kind, from the world file or injected at run time, deterministic by seed."""

from __future__ import annotations

import numpy as np
import pytest

from sim.engine import Simulation
from sim.faults import FaultInjector, nan_readings, obstacle_at
from sim.lidar import Lidar
from sim.physics import World
from sim.worldfile import Circle, Fault, load_world

CLEAN = np.full(360, 2.0)


def _scan(fault: Fault, t: float = 1.0, seed: int = 0):
    return FaultInjector([fault], seed=seed).apply(t, CLEAN)


@pytest.mark.parametrize("kind,check", [
    ("nan", np.isnan),
    ("inf", np.isposinf),
    ("neg_inf", np.isneginf),
    ("below_min", lambda r: r < Lidar().range_min),
    ("above_max", lambda r: np.isfinite(r) & (r > Lidar().range_max)),
], ids=["nan", "inf", "neg_inf", "below_min", "above_max"])
def test_per_beam_faults_hit_the_given_fraction(kind: str, check) -> None:
    scan = _scan(Fault(kind=kind, start=0.5, end=2.0, fraction=0.25))
    assert len(scan.ranges) == 360
    assert int(check(scan.ranges).sum()) == 90
    assert int((scan.ranges == 2.0).sum()) == 270


def test_faults_only_within_their_span() -> None:
    fault = nan_readings(0.5, 2.0, fraction=0.5)
    assert not np.isnan(_scan(fault, t=0.4).ranges).any()
    assert np.isnan(_scan(fault, t=0.5).ranges).any()
    assert not np.isnan(_scan(fault, t=2.0).ranges).any()


def test_beam_choice_is_deterministic_by_seed() -> None:
    fault = nan_readings(0.0, None, fraction=0.1)
    a, b = _scan(fault, seed=1).ranges, _scan(fault, seed=1).ranges
    c = _scan(fault, seed=2).ranges
    assert np.array_equal(np.isnan(a), np.isnan(b))
    assert not np.array_equal(np.isnan(a), np.isnan(c))


def test_empty_and_wrong_length_scans() -> None:
    assert len(_scan(Fault(kind="empty")).ranges) == 0
    scan = _scan(Fault(kind="wrong_length", length=100))
    assert len(scan.ranges) == 100 and len(scan.intensities) == 100
    assert len(_scan(Fault(kind="wrong_length", length=360)).ranges) == 359
    assert len(_scan(Fault(kind="wrong_length", length=400)).ranges) == 400


def test_dropout_publishes_nothing() -> None:
    injector = FaultInjector([Fault(kind="dropout", start=1.0, end=2.0)])
    assert injector.apply(0.9, CLEAN) is not None
    assert injector.apply(1.5, CLEAN) is None
    assert injector.apply(2.0, CLEAN) is not None


def test_obstacle_appears_at_its_time_and_blocks_the_robot() -> None:
    sim = Simulation(World(load_world("empty_room")))
    sim.inject(obstacle_at(0.5, Circle(center=(3.5, 3.0), radius=0.1)))
    # The far wall, from the scanner 3.2 cm behind the centre, give or take the noise.
    assert sim.lidar.scan(sim.world)[0] == pytest.approx(2.975 + 0.032, abs=0.05)
    sim.world.set_command(0.3, 0.0)
    scans = [out.scan for out in (sim.step() for _ in range(600)) if out.scan is not None]
    assert scans[0].ranges[0] > 2.0  # before 0.5 s: nothing placed yet
    assert sim.world.pose[0] == pytest.approx(3.5 - 0.1 - 0.105, abs=0.005)
    assert scans[-1].ranges[0] == pytest.approx(0.105 + 0.032, abs=0.05)  # touching it
    assert sim.recording.collisions and sim.recording.collisions[0].t >= 0.5
    sim.reset()
    assert len(sim.world.geometry[1]) == 0
    for _ in range(120):
        sim.step()
    assert len(sim.world.geometry[1]) == 1  # placed again after the reset


def test_obstacles_are_looked_for_only_while_one_is_pending() -> None:
    faults = FaultInjector([nan_readings(0.0)])
    assert not faults.obstacles_pending  # the simulation skips due_obstacles each step
    faults.add(obstacle_at(1.0, Circle(center=(1.0, 1.0), radius=0.1)))
    faults.add(obstacle_at(2.0, Circle(center=(2.0, 1.0), radius=0.1)))
    assert faults.obstacles_pending
    assert faults.due_obstacles(0.5) == []
    assert len(faults.due_obstacles(1.0)) == 1 and faults.obstacles_pending
    assert len(faults.due_obstacles(2.5)) == 1 and not faults.obstacles_pending
    faults.reset()
    assert faults.obstacles_pending


def test_faults_from_the_world_file(tmp_path) -> None:
    path = tmp_path / "faulty.yaml"
    path.write_text("seed: 7\nfaults:\n  - {kind: dropout, start: 0.0, end: 0.25}\n"
                    "  - {kind: nan, start: 0.0, fraction: 1.0}\n")
    sim = Simulation(World(load_world(path)))
    outs = [sim.step() for _ in range(100)]
    due = [o for o in outs if o.scan_due]
    assert [o.scan is None for o in due] == [True, True, False, False, False]
    assert np.isnan(due[-1].scan.ranges).all()
