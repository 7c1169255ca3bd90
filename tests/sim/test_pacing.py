"""The pacing scheduler alone: a fake wall clock and fake student processes, no ROS.

Each test runs ticks the way the bridge does (plan, publish, pace) and checks the wall
times the ticks went at, the sim time they made, and how the holds ended.
"""

from __future__ import annotations

import collections
import math
import threading
from collections.abc import Callable
from dataclasses import dataclass, field

import pytest

from sim.pacing import Pacer, PacingPolicy, Tick
from sim.procstate import IDLE, ProcessState

DT = 0.005  # the world's physics step
WALL = 10.0  # real seconds a thread test waits at most for the other thread


class FakeClock:
    """Wall time that moves only when the pacer sleeps or a test says so."""

    def __init__(self) -> None:
        self.now = 100.0
        self.ticks: list[float] = []  # when each tick went out
        self.waiting = threading.Event()  # set when a thread waits for the pacer to resume

    def monotonic(self) -> float:
        return self.now

    def sleep(self, seconds: float) -> None:
        self.now += max(0.0, seconds)

    def wait(self, condition: threading.Condition, predicate: Callable[[], bool]) -> None:
        self.waiting.set()
        assert condition.wait_for(predicate, timeout=WALL), "never woken"


@dataclass
class FakeProcess:
    """A student process as /proc would show it, as a function of the fake time.

    It is busy until ``idle_at`` and meanwhile gets ``cpu_share`` seconds of CPU per wall
    second (1: it computes; 0: it is runnable but starved of a CPU).  It hears the ticks
    that went out from ``hears_from`` on: each reaches it ``delay`` after it went out, and
    it then computes for ``reaction`` (at least a microsecond: a message costs some CPU).
    With ``middleware_delay`` set, its middleware's threads take every tick in that long
    after it went out, for a microsecond of CPU, whether or not the program hears it.
    Until ``blocked_until`` one of its own threads sleeps in the kernel uninterruptibly
    (state D: a page being read in), using no CPU."""

    clock: FakeClock
    idle_at: float = math.inf
    cpu_share: float = 1.0
    hears_from: float = -math.inf
    delay: float = 0.0
    reaction: float = 0.0
    middleware_delay: float | None = None
    blocked_until: float = -math.inf

    def __call__(self, pid: int) -> ProcessState:
        now = self.clock.now
        busy = now < self.idle_at
        cpu = min(now, self.idle_at) * self.cpu_share
        for sent in (t for t in self.clock.ticks if t >= self.hears_from):
            got = sent + self.delay
            if got <= now:
                cpu += min(now - got, self.reaction) + 1e-6
                busy = busy or now < got + self.reaction
        middleware = 0.0
        if self.middleware_delay is not None:
            middleware = 1e-6 * sum(1 for t in self.clock.ticks
                                    if t + self.middleware_delay <= now)
        blocked = now < self.blocked_until
        return ProcessState(busy=busy, cpu_ns=round((cpu + middleware) * 1e9),
                            own_busy=busy, own_cpu_ns=round(cpu * 1e9), blocked=blocked)


@dataclass
class Run:
    """Ticks driven like the bridge's physics thread, with what each one did."""

    pacer: Pacer
    clock: FakeClock
    sim_time: float = 0.0
    published: list[float] = field(default_factory=list)  # wall time of each tick
    ticks: list[Tick] = field(default_factory=list)

    def tick(self, work: Callable[[int], float] = lambda steps: 0.0) -> Tick:
        """One tick: plan it, publish it (taking ``work(steps)`` wall seconds), pace it."""
        tick = self.pacer.next_tick()
        assert tick is not None
        self.pacer.about_to_publish()
        self.published.append(self.clock.now)
        self.clock.ticks.append(self.clock.now)
        self.clock.sleep(work(tick.steps))
        self.sim_time += tick.steps * DT
        self.pacer.note_tick(self.sim_time)
        self.pacer.pace(tick)
        self.ticks.append(tick)
        return tick

    def ticks_for(self, n: int, work: Callable[[int], float] = lambda steps: 0.0) -> Run:
        for _ in range(n):
            self.tick(work)
        return self

    def gaps(self) -> list[float]:
        return [b - a for a, b in zip(self.published, self.published[1:], strict=False)]


def make(rtf: float = 1.0, process: Callable[[int], ProcessState] | None = None,
         **policy: float) -> Run:
    clock = FakeClock()
    pacer = Pacer(DT, rtf, PacingPolicy(**policy), clock=clock,
                  read_process=process or (lambda pid: IDLE))
    return Run(pacer, clock)


# -- deadlines -------------------------------------------------------------------------
@pytest.mark.parametrize("rtf", [0.5, 1.0, 2.0, 4.0])
def test_ticks_follow_the_real_time_factor(rtf: float) -> None:
    run = make(rtf).ticks_for(41)
    assert {t.steps for t in run.ticks} == {round(rtf / 20 / DT)}  # rtf / 20 Hz of sim time
    assert run.gaps() == pytest.approx([0.05] * 40, abs=1e-9)  # 20 Hz of wall time
    assert run.pacer.effective_rtf == pytest.approx(rtf)
    assert run.pacer.counts == {"free": 41}


def test_rtf_zero_adapts_the_tick_to_fill_the_clock_period() -> None:
    """At RTF 0 a tick's work (1 ms per step here) grows to fill 1 / clock_hz."""
    def work(steps: int) -> float:
        return steps * 0.001

    run = make(0.0).ticks_for(10, work)
    assert [t.steps for t in run.ticks[:5]] == [10, 20, 40, 50, 50]  # from 1 / clock_hz
    run.pacer.forget_rate()
    run.ticks_for(20, work)
    assert {t.steps for t in run.ticks[4:]} == {50}  # 50 ms of work: the whole 0.05 s
    assert all(gap >= 0.05 - 1e-9 for gap in run.gaps())  # still at most 20 per second
    assert run.pacer.effective_rtf == pytest.approx(5.0)


def test_rtf_zero_tick_is_capped_and_shrinks_when_heavy() -> None:
    run = make(0.0, max_tick=2.0).ticks_for(20, work=lambda steps: steps * 1e-6)
    assert run.ticks[-1].steps == 400  # max_tick: 2 s of sim time at once
    heavy = make(0.0).ticks_for(10, work=lambda steps: steps * 0.01)
    assert heavy.ticks[0].steps == 10 and heavy.ticks[-1].steps == 5  # halved, then fits


@pytest.mark.parametrize("clock_hz,rtf", [(20, 1.0), (45, 1.0), (30, 1.0), (20, 0.3),
                                          (50, 2.0), (7, 3.0), (20, 0.01), (45, 0.0)])
def test_never_more_than_clock_hz_ticks_per_wall_second(clock_hz: float, rtf: float) -> None:
    run = make(rtf, clock_hz=clock_hz).ticks_for(60)
    assert min(run.gaps()) >= 1 / clock_hz - 1e-9
    if rtf > 0:  # and the sim time still keeps the real-time factor
        assert run.pacer.effective_rtf == pytest.approx(rtf)


def test_no_catch_up_after_a_stall() -> None:
    """A tick that takes 1 s (a slow publish) moves the schedule; no burst follows."""
    run = make(1.0)
    run.ticks_for(5)
    run.tick(work=lambda steps: 1.0)
    run.ticks_for(20)
    gaps = run.gaps()
    assert gaps[:6] == pytest.approx([0.05] * 5 + [1.0], abs=1e-9)
    assert gaps[6:] == pytest.approx([0.05] * 19, abs=1e-9)  # on from the late tick
    assert run.pacer.effective_rtf < 0.9  # sim time just ran slower


# -- holding for the student's process -------------------------------------------------
def test_hold_ends_when_the_process_is_idle() -> None:
    clock = FakeClock()
    process = FakeProcess(clock, idle_at=clock.now + 0.03)
    run = Run(Pacer(DT, 1.0, clock=clock, read_process=process), clock)
    run.pacer.watch(4242)
    run.tick()  # idle after 30 ms: before the 50 ms deadline, which it then keeps
    assert run.pacer.counts == {"idle": 1}
    assert run.pacer.longest_hold == pytest.approx(0.03, abs=0.001)
    run.ticks_for(3)
    assert run.pacer.counts == {"idle": 4}
    assert run.gaps() == pytest.approx([0.05] * 3, abs=1e-9)


@pytest.mark.parametrize("share,hold", [(1.0, 0.05), (0.5, 0.1), (0.25, 0.2)])
def test_hold_ends_when_the_cpu_budget_is_used(share: float, hold: float) -> None:
    """A busy process is let go after cpu_budget (50 ms) of CPU, whatever its share (here
    without a reserve: see the reserve's tests below)."""
    clock = FakeClock()
    run = Run(Pacer(DT, 1.0, PacingPolicy(cpu_reserve=0.0), clock=clock,
                    read_process=FakeProcess(clock, cpu_share=share)), clock)
    run.pacer.watch(4242)
    run.ticks_for(5)
    assert run.pacer.counts == {"budget": 5}
    # settle (1 ms), then the budget's worth of CPU at this share
    assert run.pacer.longest_hold == pytest.approx(0.001 + hold, abs=0.001)
    assert all(gap == pytest.approx(max(0.05, 0.001 + hold), abs=0.001) for gap in run.gaps())


@dataclass
class Bursts:
    """A process that reacts to each tick for 1 ms and computes, at a whole CPU, during
    the given spans of wall time (a callback that now and then takes long)."""

    clock: FakeClock
    spans: list[tuple[float, float]] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.ticks = FakeProcess(self.clock, idle_at=self.clock.now, reaction=0.001)

    def burst(self, seconds: float) -> None:
        """Compute for ``seconds`` from now."""
        self.spans.append((self.clock.now, self.clock.now + seconds))

    def __call__(self, pid: int) -> ProcessState:
        now, state = self.clock.now, self.ticks(pid)
        computed = sum(min(now, end) - start for start, end in self.spans if now > start)
        busy = state.busy or any(start <= now < end for start, end in self.spans)
        return ProcessState(busy=busy, cpu_ns=state.cpu_ns + round(computed * 1e9))


def test_a_burst_is_waited_for_from_the_reserve() -> None:
    """A usually idle process that computes for 0.3 s of CPU after a tick (a thread pool
    catching up) holds that tick until it is done, once its idle ticks have banked enough
    (49 ms each here); without a reserve the tick went on after its 50 ms budget."""
    for reserve, outcome, hold in ((2.0, "idle", 0.3), (0.0, "budget", 0.05)):
        clock = FakeClock()
        process = Bursts(clock)
        run = Run(Pacer(DT, 1.0, PacingPolicy(cpu_reserve=reserve), clock=clock,
                        read_process=process), clock)
        run.pacer.watch(4242)
        run.ticks_for(6)
        process.burst(0.3)
        run.tick()
        assert run.pacer.counts == collections.Counter(["idle"] * 6 + [outcome])
        assert run.pacer.longest_hold == pytest.approx(hold, abs=0.002)
        assert run.pacer.bursts == (1 if reserve else 0)


def test_the_reserve_is_paid_back_while_idle() -> None:
    """The reserve starts empty and fills from ticks that use less than the budget, up to
    cpu_reserve; a burst spends it, and a later burst is waited for once it is paid back."""
    clock = FakeClock()
    process = Bursts(clock)
    run = Run(Pacer(DT, 1.0, PacingPolicy(cpu_reserve=0.5), clock=clock,
                    read_process=process), clock)
    run.pacer.watch(4242)
    process.burst(0.5)
    run.tick()  # nothing banked yet: the tick goes on after the budget
    assert run.pacer.counts == {"budget": 1}
    clock.sleep(0.5)  # the burst ends
    run.ticks_for(12)  # each banks 49 ms: 0.5 s, full
    process.burst(0.5)
    run.tick()  # 0.5 s: the budget and 0.45 s of the reserve
    assert run.pacer.counts == {"budget": 1, "idle": 13}
    process.burst(0.5)
    run.tick()  # 0.05 s of reserve left: the tick goes on after 0.1 s
    assert run.pacer.counts == {"budget": 2, "idle": 13}
    clock.sleep(0.5)
    run.ticks_for(12)
    process.burst(0.5)
    run.tick()
    assert run.pacer.counts == {"budget": 2, "idle": 26}
    assert run.pacer.bursts == 3  # the first burst had nothing to draw on


def test_a_busy_loop_has_no_reserve() -> None:
    """A process that always computes banks nothing: exactly cpu_budget a tick, so the
    reserve does not slow the world for busy loops."""
    clock = FakeClock()
    run = Run(Pacer(DT, 1.0, clock=clock, read_process=FakeProcess(clock)), clock)
    run.pacer.watch(4242)
    run.ticks_for(6)
    assert run.pacer.counts == {"budget": 6}
    assert run.gaps() == pytest.approx([0.051] * 5, abs=0.002)
    assert run.pacer.bursts == 0


def test_a_starved_process_holds_until_the_limit() -> None:
    """Runnable but no CPU (a busy machine): the world waits for it, hold_cap not counting
    that time, until hold_limit (10 s) of wall time."""
    clock = FakeClock()
    run = Run(Pacer(DT, 1.0, PacingPolicy(clock_hz=50.0), clock=clock,
                    read_process=FakeProcess(clock, cpu_share=0.0)), clock)
    run.pacer.watch(4242)
    run.ticks_for(3)
    assert run.pacer.counts == {"cap": 3}
    assert 10.0 <= run.pacer.longest_hold < 10.0 + 0.005
    assert run.pacer.effective_rtf < 0.01  # 0.02 s of sim time per 10 s held


def test_a_process_starved_for_longer_than_the_cap_is_waited_for() -> None:
    """A node that waits 3 s for a CPU, then reacts, is not overtaken at hold_cap: the
    tick goes once it is done (a busy machine must not change what the node saw)."""
    clock = FakeClock()
    process = FakeProcess(clock, cpu_share=0.0, idle_at=clock.now + 3.0)
    run = Run(Pacer(DT, 1.0, clock=clock, read_process=process), clock)
    run.pacer.watch(4242)
    run.tick()
    assert run.pacer.counts == {"idle": 1}
    assert run.pacer.longest_hold == pytest.approx(3.0, abs=0.005)


def test_a_process_that_computes_slowly_is_let_go_at_the_cap() -> None:
    """Busy and getting some CPU, but less than its budget in hold_cap (2 s): its time
    counts, and the tick goes at the cap."""
    clock = FakeClock()
    run = Run(Pacer(DT, 1.0, PacingPolicy(cpu_reserve=0.0), clock=clock,
                    read_process=FakeProcess(clock, cpu_share=0.01)), clock)
    run.pacer.watch(4242)
    run.tick()
    assert run.pacer.counts == {"cap": 1}
    assert 2.0 <= run.pacer.longest_hold < 2.0 + 0.001


def _timed_readings(clock: FakeClock, process: FakeProcess) -> tuple[Run, list[float]]:
    """A run whose pacer reads ``process``, and the fake times of its readings."""
    readings: list[float] = []

    def read(pid: int) -> ProcessState:
        readings.append(clock.now)
        return process(pid)

    pacer = Pacer(DT, 1.0, PacingPolicy(clock_hz=50.0, hold_limit=2.0), clock=clock,
                  read_process=read)
    return Run(pacer, clock), readings


def test_readings_of_a_starved_process_back_off_to_the_most_allowed() -> None:
    """While the process waits for a CPU, the pause between readings doubles up to
    ``starved_poll_max``: the world leaves the cores to the processes it waits for."""
    clock = FakeClock()
    run, readings = _timed_readings(clock, FakeProcess(clock, cpu_share=0.0))
    run.pacer.watch(4242)
    run.tick()
    assert run.pacer.counts == {"cap": 1}  # the same outcome as reading every 0.5 ms
    pauses = [round(b - a, 6) for a, b in zip(readings[1:], readings[2:], strict=False)]
    assert pauses[:5] == [0.0005, 0.001, 0.002, 0.004, 0.004]  # from the first look on
    assert set(pauses[3:]) == {0.004}
    assert len(readings) < 2.0 / 0.004 + 5  # about 500 readings in 2 s, not 4000


def test_a_process_that_computes_is_read_every_poll_interval() -> None:
    """A process whose CPU time grows is read at ``poll_interval``, as before."""
    clock = FakeClock()
    run, readings = _timed_readings(clock, FakeProcess(clock, idle_at=clock.now + 0.01))
    run.pacer.watch(4242)
    run.tick()
    assert run.pacer.counts == {"idle": 1}
    pauses = {round(b - a, 6) for a, b in zip(readings[1:], readings[2:], strict=False)}
    assert pauses == {0.0005}


def test_held_seconds_count_holds_past_the_deadline_only() -> None:
    """A hold within the tick's period costs no wall time; past it, every second counts."""
    clock = FakeClock()
    process = FakeProcess(clock, idle_at=clock.now + 0.03)
    run = Run(Pacer(DT, 1.0, clock=clock, read_process=process), clock)
    run.pacer.watch(4242)
    run.ticks_for(3)  # idle after 30 ms: within the 50 ms period
    assert run.pacer.held_seconds == 0.0
    starved = Run(Pacer(DT, 1.0, PacingPolicy(clock_hz=50.0, hold_limit=2.0), clock=clock,
                        read_process=FakeProcess(clock, cpu_share=0.0)), clock)
    starved.pacer.watch(4242)
    starved.ticks_for(3)  # held to the 2 s limit, the period being 20 ms
    assert starved.pacer.held_seconds == pytest.approx(3 * (2.0 - 0.02), abs=0.003)


def test_a_process_read_idle_once_is_read_again() -> None:
    """One reading of a process goes thread by thread, so a thread woken by another just
    after it was read, its waker asleep by the time it is read, makes a working process
    read idle once. The tick goes only when a second reading agrees."""
    clock = FakeClock()

    def read(pid: int) -> ProcessState:
        t = clock.now - clock.ticks[-1] if clock.ticks else 0.0
        before = len(clock.ticks) * 0.02  # CPU seconds of the ticks before
        if 0.0018 <= t < 0.0023:  # the reading that falls between waker and woken
            return ProcessState(busy=False, cpu_ns=round((before + 0.0018) * 1e9))
        used = min(t, 0.0018) + max(0.0, min(t, 0.01) - 0.0023)
        return ProcessState(busy=t < 0.01, cpu_ns=round((before + used) * 1e9))

    run = Run(Pacer(DT, 1.0, clock=clock, read_process=read), clock)
    run.pacer.watch(4242)
    run.ticks_for(3)
    assert run.pacer.counts == {"idle": 3}
    assert run.pacer.longest_hold == pytest.approx(0.0105, abs=0.001)  # done at 10 ms


def test_every_watched_process_must_be_done() -> None:
    clock = FakeClock()
    idle_soon, computing = FakeProcess(clock, idle_at=clock.now), FakeProcess(clock)
    processes = {1: idle_soon, 2: computing}
    run = Run(Pacer(DT, 1.0, PacingPolicy(cpu_reserve=0.0), clock=clock,
                    read_process=lambda pid: processes[pid](pid)), clock)
    run.pacer.watch(1)
    run.pacer.watch(2)
    run.tick()
    assert run.pacer.counts == {"budget": 1}  # one idle, the other had its share
    run.pacer.unwatch(2)
    run.tick()
    assert run.pacer.counts == {"budget": 1, "idle": 1}
    run.pacer.watch(None)
    run.tick()
    assert run.pacer.counts == {"budget": 1, "idle": 1, "free": 1}


def test_a_process_blocked_in_the_kernel_is_waited_for() -> None:
    """A node that reacts to a tick and then waits for a page from disk (state D) is not
    done: read idle, the world went on for four ticks while a correct node's first warning
    loaded, and its stop came late (benchmarks/RESULTS.md)."""
    clock = FakeClock()
    process = FakeProcess(clock, idle_at=clock.now, reaction=0.002,
                          blocked_until=clock.now + 0.3)
    run = Run(Pacer(DT, 1.0, clock=clock, read_process=process), clock)
    run.pacer.watch(4242)
    run.tick()
    assert run.pacer.counts == {"idle": 1}
    assert run.pacer.longest_hold == pytest.approx(0.3, abs=0.002)
    run.ticks_for(3)  # no longer blocked: as any idle process
    assert run.pacer.counts == {"idle": 4} and run.pacer.blocked_waits == 1
    assert run.gaps()[1:] == pytest.approx([0.05] * 2, abs=1e-9)


def test_a_process_that_stays_blocked_costs_its_blocked_reserve_once() -> None:
    """A thread that never leaves state D (a vfork child that never starts) holds sim
    time for ``blocked_reserve`` of wall time in all, then reads as done."""
    clock = FakeClock()
    process = FakeProcess(clock, idle_at=clock.now, reaction=0.002, blocked_until=math.inf)
    run = Run(Pacer(DT, 1.0, PacingPolicy(blocked_reserve=0.4), clock=clock,
                    read_process=process), clock)
    run.pacer.watch(4242)
    run.ticks_for(5)
    assert run.pacer.counts == {"idle": 5} and run.pacer.blocked_waits == 1
    assert run.pacer.longest_hold == pytest.approx(0.4, abs=0.005)
    assert run.gaps()[1:] == pytest.approx([0.05] * 3, abs=1e-9)  # then, as if done
    run.pacer.watch(4243)  # a new process (its next start) has a full store
    before = clock.now
    run.tick()
    assert clock.now - before == pytest.approx(0.4, abs=0.005)


def test_a_gone_process_reads_idle() -> None:
    run = make(1.0, process=lambda pid: IDLE)
    run.pacer.watch(2**22 + 1)
    run.ticks_for(2)
    assert run.pacer.counts == {"idle": 2}
    assert run.pacer.longest_hold == pytest.approx(0.001)  # only the settle


def test_an_idle_process_is_held_for_until_it_hears_the_tick() -> None:
    """On a loaded machine a tick may reach the student's socket late: read idle before
    then, the process has not started on it, and the next tick must not overtake it."""
    clock = FakeClock()
    process = FakeProcess(clock, idle_at=clock.now, delay=0.02, reaction=0.01)
    run = Run(Pacer(DT, 1.0, clock=clock, read_process=process), clock)
    run.pacer.watch(4242)
    run.ticks_for(4)
    assert run.pacer.counts == {"idle": 4}
    assert run.pacer.late_deliveries == 4
    assert run.pacer.longest_hold == pytest.approx(0.03, abs=0.001)  # heard, then done
    assert run.gaps() == pytest.approx([0.05] * 3, abs=1e-9)  # within the period: no cost
    prompt = FakeProcess(clock, idle_at=clock.now, reaction=0.01)
    run = Run(Pacer(DT, 1.0, clock=clock, read_process=prompt), clock)
    run.pacer.watch(4242)
    run.ticks_for(4)
    assert run.pacer.counts == {"idle": 4} and run.pacer.late_deliveries == 0


def test_a_process_that_hears_no_ticks_costs_one_hear_timeout() -> None:
    """No /clock subscription, or hung before making its node: waited for once."""
    clock = FakeClock()
    process = FakeProcess(clock, idle_at=clock.now, hears_from=math.inf)
    run = Run(Pacer(DT, 1.0, clock=clock, read_process=process), clock)
    run.pacer.watch(4242)
    run.ticks_for(6)
    assert run.pacer.counts == {"unheard": 1, "idle": 5}
    assert run.pacer.late_deliveries == 0
    assert run.gaps() == pytest.approx([0.5] + [0.05] * 4, abs=0.002)
    process.hears_from, process.delay = clock.now, 0.02  # it hears, late: not waited for
    run.tick()
    assert run.pacer.late_deliveries == 0
    run.ticks_for(2)  # having heard the tick before, it is waited for again
    assert run.pacer.late_deliveries == 2


def test_a_tick_only_the_middleware_took_in_is_not_heard() -> None:
    """A node's middleware takes each ``/clock`` in on its own threads, whether or not
    the node's executor wakes for it (seen at load 24: an executor woke only at its
    ``spin_once`` timeout, 0.1 s later, while ticks went on as heard). A tick is heard
    when the program's own threads run; an executor that never wakes is deaf, once."""
    clock = FakeClock()
    process = FakeProcess(clock, idle_at=clock.now, delay=0.1, reaction=0.01,
                          middleware_delay=0.0)
    run = Run(Pacer(DT, 1.0, clock=clock, read_process=process), clock)
    run.pacer.watch(4242)
    run.ticks_for(4)
    assert run.pacer.counts == {"idle": 4} and run.pacer.late_deliveries == 4
    assert run.pacer.longest_hold == pytest.approx(0.11, abs=0.002)  # woken, then done
    assert run.gaps() == pytest.approx([0.11] * 3, abs=0.002)  # the next tick waited
    asleep = FakeProcess(clock, idle_at=clock.now, hears_from=math.inf,
                         middleware_delay=0.0)
    run = Run(Pacer(DT, 1.0, clock=clock, read_process=asleep), clock)
    run.pacer.watch(4242)
    run.ticks_for(4)
    assert run.pacer.counts == {"unheard": 1, "idle": 3}
    assert run.gaps() == pytest.approx([0.5] + [0.05] * 2, abs=0.002)


def test_a_tick_heard_after_the_timeout_still_counts_as_heard() -> None:
    """Whether a process heard a tick is judged up to the next tick: one delivery later
    than hear_timeout does not stop the pacing from waiting for the following ones."""
    clock = FakeClock()
    process = FakeProcess(clock, idle_at=clock.now, delay=0.7)
    run = Run(Pacer(DT, 1.0, clock=clock, read_process=process), clock)
    run.pacer.watch(4242)
    run.tick()
    assert run.pacer.counts == {"unheard": 1}
    clock.sleep(0.3)  # it hears the tick 0.7 s after it went out
    process.delay = 0.02
    run.ticks_for(2)
    assert run.pacer.counts == {"unheard": 1, "idle": 2} and run.pacer.late_deliveries == 2


def test_a_tick_still_on_its_way_is_waited_for_past_the_hear_timeout() -> None:
    """While the kernel still holds packets it has not delivered (its receive work left
    to ksoftirqd on a busy machine), the tick may be on its way: the process is not given
    up on as deaf, and the next tick does not overtake it."""
    clock = FakeClock()
    process = FakeProcess(clock, idle_at=clock.now, delay=0.7, reaction=0.01)
    run = Run(Pacer(DT, 1.0, clock=clock, read_process=process,
                    delivering=lambda: clock.now < clock.ticks[-1] + 0.7), clock)
    run.pacer.watch(4242)
    run.ticks_for(3)
    assert run.pacer.counts == {"idle": 3} and run.pacer.late_deliveries == 3
    assert run.pacer.longest_hold == pytest.approx(0.71, abs=0.002)  # heard, then done
    deaf = FakeProcess(clock, idle_at=clock.now, hears_from=math.inf)
    run = Run(Pacer(DT, 1.0, clock=clock, read_process=deaf,
                    delivering=lambda: clock.now < clock.ticks[-1] + 0.7), clock)
    run.pacer.watch(4242)
    run.ticks_for(2)  # nothing more in flight after 0.7 s: deaf, once
    assert run.pacer.counts == {"unheard": 1, "idle": 1}
    assert run.gaps() == pytest.approx([0.7], abs=0.005)


def test_a_tick_waits_for_the_world_to_take_in_what_was_sent() -> None:
    """A node idle after publishing has sent its command, but the world's own receive
    thread may still wait for a CPU: the next tick goes once the world has taken it in,
    and only then, for up to receive_timeout."""
    clock = FakeClock()
    process = FakeProcess(clock, idle_at=clock.now, reaction=0.005)

    def receiving() -> bool:  # each tick's message is taken in 0.03 s after it went out
        return clock.now < clock.ticks[-1] + 0.03

    run = Run(Pacer(DT, 1.0, clock=clock, read_process=process, receiving=receiving),
              clock)
    run.pacer.watch(4242)
    run.ticks_for(3)
    assert run.pacer.counts == {"idle": 3} and run.pacer.receipts_awaited == 3
    assert run.pacer.longest_hold == pytest.approx(0.03, abs=0.001)
    assert run.gaps() == pytest.approx([0.05] * 2, abs=1e-9)  # within the period: no cost
    never = Run(Pacer(DT, 1.0, PacingPolicy(receive_timeout=0.2), clock=clock,
                      read_process=process, receiving=lambda: True), clock)
    never.pacer.watch(4242)
    never.ticks_for(3)  # receiving never ends: each hold is cut at receive_timeout
    assert never.pacer.counts == {"idle": 3} and never.pacer.receipts_awaited == 3
    assert never.gaps() == pytest.approx([0.206] * 2, abs=0.002)  # reaction, then 0.2 s
    free = Run(Pacer(DT, 1.0, clock=clock, receiving=lambda: True), clock).ticks_for(3)
    assert free.pacer.counts == {"free": 3} and free.pacer.receipts_awaited == 0
    assert free.gaps() == pytest.approx([0.05] * 2, abs=1e-9)  # nothing watched: no hold


def test_a_process_being_stopped_is_not_waited_for_to_hear() -> None:
    """Once the grader stops a node, it stops hearing ticks: no hear_timeout for that."""
    clock = FakeClock()
    process = FakeProcess(clock, idle_at=clock.now, reaction=0.01)
    run = Run(Pacer(DT, 1.0, PacingPolicy(cpu_reserve=0.0), clock=clock,
                    read_process=process), clock)
    run.pacer.watch(4242)
    run.ticks_for(2)
    run.pacer.closing(4242)
    process.hears_from = math.inf  # its node is gone; the process is still exiting
    run.ticks_for(3)
    assert run.pacer.counts == {"idle": 5}
    assert run.gaps() == pytest.approx([0.05] * 4, abs=1e-9)
    process.idle_at = math.inf  # still busy (cleaning up): held for its work as before
    run.tick()
    assert run.pacer.counts == {"idle": 5, "budget": 1}


def test_a_long_hold_is_not_caught_up() -> None:
    """After holds of 2 s, the next free ticks keep 1 / clock_hz apart."""
    clock = FakeClock()
    process = FakeProcess(clock, cpu_share=0.0, idle_at=clock.now + 5.0)
    run = Run(Pacer(DT, 1.0, PacingPolicy(hold_limit=2.0), clock=clock,
                    read_process=process), clock)
    run.pacer.watch(4242)
    run.ticks_for(10)
    assert run.pacer.counts == {"cap": 2, "idle": 8}  # the third hold ends at 5 s
    assert run.gaps()[3:] == pytest.approx([0.05] * 6, abs=1e-9)


# -- held, paused, stopped -------------------------------------------------------------
def test_held_blocks_ticks_until_the_block_ends() -> None:
    """The start-up hold: a ticking thread waits inside held(); the schedule restarts."""
    run = make(1.0)
    run.ticks_for(3)
    got: list[Tick | None] = []
    with run.pacer.held():
        ticker = threading.Thread(target=lambda: got.append(run.pacer.next_tick()))
        ticker.start()
        assert run.clock.waiting.wait(WALL)  # it is blocked in next_tick
        run.clock.sleep(7.0)  # seven wall seconds of start-up pass
        assert got == [] and run.pacer.paused
    ticker.join(WALL)
    assert got and got[0] is not None and not run.pacer.paused
    run.pacer.pace(got[0])
    assert run.clock.now == pytest.approx(100.0 + 3 * 0.05 + 7.0 + 0.05)  # one period on


def test_held_inside_a_pause_stays_paused() -> None:
    run = make(1.0)
    run.pacer.pause()
    with run.pacer.held():
        pass
    assert run.pacer.paused
    run.pacer.resume()
    assert run.tick().steps == 10


def test_stop_releases_a_waiting_thread() -> None:
    run = make(1.0)
    run.pacer.pause()
    got: list[Tick | None] = []
    ticker = threading.Thread(target=lambda: got.append(run.pacer.next_tick()))
    ticker.start()
    assert run.clock.waiting.wait(WALL)
    run.pacer.stop()
    ticker.join(WALL)
    assert got == [None]


def test_bad_settings_are_refused() -> None:
    with pytest.raises(ValueError):
        make(-1.0)
    with pytest.raises(ValueError):
        make(1.0, clock_hz=0.0)
    with pytest.raises(ValueError):
        make(1.0).pacer.set_real_time_factor(-0.5)
