"""When the world's next clock tick may go: the pacing, as a scheduler without ROS.

Simulation time must not run ahead of a student process that is slow to react, or
verdicts would depend on how busy the machine is.  The world advances in *clock ticks*
(a whole number of physics steps, then one ``/clock``); the :class:`Pacer` decides how
long each tick is and when the next one may go.  It reads time only through a
:class:`Clock` and the student's process only through a
:data:`~sim.procstate.ProcessReader`, so tests drive it with a fake clock and fake
processes, in milliseconds.

* **Tick length.**  ``/clock`` goes out at most ``clock_hz`` times per *wall* second, 20 by
  default: Jazzy's MultiThreadedExecutor keeps a 10 Hz sim-time timer exact at 20 Hz but
  stutters from about 50 Hz (measured; the exercises' ``clock_hz`` has the same default).
  At a real-time factor ``r > 0`` a tick is the fewest physics steps that make at least
  ``r / clock_hz`` of sim time (0.05 s at RTF 1), so the cap holds however ``r`` and the
  step divide.  At ``r == 0`` ("as fast as the graph keeps up") the tick length adapts so
  that one tick's work fills ``1 / clock_hz`` of wall time, up to ``max_tick`` (2 s): a
  node then sees its clock jump by up to ``max_tick`` at once, so graders who care about
  timer granularity pick a finite RTF.
* **Wall deadline.**  A tick is given ``steps * dt / r`` wall seconds (``1 / clock_hz`` at
  RTF 0).  There is no catch-up: a late tick moves the schedule, so sim time just runs
  slower; it never bursts to make up for a stall or a hold.
* **Hold for the student.**  With watched processes, the next tick also waits until none
  of them is running or runnable, or each busy one has used ``cpu_budget`` (50 ms) of CPU
  since the tick, with ``hold_cap`` (2 s) of wall time as the last resort.  A process that
  cannot get a CPU on a busy machine thus holds sim time back however long it waits, while
  one that busy-loops has had its share after 50 ms of CPU and only slows the world.  (A
  wall-time cap alone, tried first, let sim time run on while a starved process waited
  for a CPU, and a correct node then failed under load.)  How each hold ended is counted
  (:attr:`Pacer.counts`; the results file's ``pacing``).
* **CPU reserve.**  A process that is usually idle may take a longer turn now and then:
  each watched process banks, up to ``cpu_reserve`` (2 s), the part of ``cpu_budget`` it
  leaves unused in each tick, and a tick's hold draws on that bank once the budget is
  used.  It starts empty, so a process that computes from the start never has one.
  Jazzy's MultiThreadedExecutor (rclpy 7.1.6, the PyPI wheel; rclpy issue 1452) loops on
  a ready callback, handing it to its thread pool again, until a worker starts it: on a
  loaded machine a correct node's main thread burnt 220-240 ms of CPU in one tick while
  timer_sync's planner slept.  A budget alone then let the tick go on without it (seen in
  CI: eight gradings on two cores, a beat lost).  A process that always computes gets
  exactly ``cpu_budget`` a tick, so a busy loop slows the world no more than before.
  Holds that drew on the reserve are counted (:attr:`Pacer.bursts`).
* **Heard first.**  Idle only counts once the process has *heard* the tick: its CPU time
  has grown since just before the tick went out (:meth:`Pacer.about_to_publish`), or it
  is running.  On a loaded machine the kernel may hand a loopback datagram to the
  student's socket late (receive work deferred to ``ksoftirqd``); a process read as idle
  meanwhile has not started on the tick, and the next tick would overtake it (a 10 Hz
  timer then skips a beat: seen in CI, eight gradings on two cores).  The hold waits up
  to ``hear_timeout`` (0.5 s) for it, if it heard the tick before: whether it did is
  judged over the whole time between the two ticks.  A process that hears no ticks (no
  ``/clock`` subscription, or hung before making its node) thus costs one
  ``hear_timeout``, not one per tick.  Ticks held this way are counted
  (:attr:`Pacer.late_deliveries`: those the pacing would otherwise have let go early).
* **Taken in.**  Then the world's own middleware must have taken in what the processes
  sent: a tick goes only once the world's receive threads are idle and the kernel holds no
  received packets (:class:`sim.procstate.Receiving`), for up to ``receive_timeout``
  (0.5 s).  A node idle after publishing its command has sent it, but on a loaded machine
  the grader's own receive thread may wait for a CPU meanwhile: with eight error_handling
  gradings on two cores, 1.5% of a correct node's commands were taken one to three ticks
  late without this wait (4.5% when an executor thread took them, and one of 100 such
  gradings lost a test).  Holds that waited for this are counted
  (:attr:`Pacer.receipts_awaited`).
* **Held.**  Inside :meth:`Pacer.held` (a student's program starting) no tick goes;
  afterwards the schedule starts afresh from that moment.

The pacer's condition is the bridge's lock: a tick runs under it, so ``pause()`` returning
means no tick starts afterwards, and waiters for sim time are woken on it.
"""

from __future__ import annotations

import collections
import contextlib
import math
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Literal, Protocol

from sim.procstate import ProcessReader, ProcessState, read_process_state

DEFAULT_CLOCK_HZ = 20.0
"""Most ``/clock`` messages per wall second; see the module's docstring for why 20."""
DEFAULT_CPU_BUDGET = 0.05
"""CPU seconds a busy student process gets after a tick before the world goes on."""

HoldOutcome = Literal["free", "idle", "budget", "unheard", "cap"]
"""How a tick's hold ended: nothing watched, all idle, CPU share used, a process that did
not hear the tick within ``hear_timeout``, or the wall cap."""


class Clock(Protocol):
    """Wall time as the pacer sees it."""

    def monotonic(self) -> float:
        """Seconds on a clock that never goes back."""
        ...

    def sleep(self, seconds: float) -> None:
        """Let ``seconds`` pass."""
        ...

    def wait(self, condition: threading.Condition, predicate: Callable[[], bool]) -> None:
        """With ``condition`` held, wait on it until ``predicate()`` holds."""
        ...


class SystemClock:
    """The real clock: ``time.monotonic`` and ``time.sleep``."""

    def monotonic(self) -> float:
        return time.monotonic()

    def sleep(self, seconds: float) -> None:
        if seconds > 0:
            time.sleep(seconds)

    def wait(self, condition: threading.Condition, predicate: Callable[[], bool]) -> None:
        condition.wait_for(predicate)


@dataclass(frozen=True)
class PacingPolicy:
    """The pacing's knobs (wall seconds unless said otherwise)."""

    clock_hz: float = DEFAULT_CLOCK_HZ
    cpu_budget: float = DEFAULT_CPU_BUDGET
    hold_cap: float = 2.0
    """Longest hold for a watched process, from the tick's publication."""
    settle: float = 0.001
    """Pause after publishing before the first look at the processes: a reading taken at
    once would often find them idle only because the messages had not reached them."""
    hear_timeout: float = 0.5
    """Longest wait, from the tick's publication, for a watched process to hear it."""
    cpu_reserve: float = 2.0
    """Most CPU seconds a watched process may bank, beyond ``cpu_budget``, for a burst."""
    poll_interval: float = 0.0005
    """Pause between two readings of the watched processes while holding a tick (a
    reading of a 16-thread rclpy process takes about 0.22 ms more).  Cheaper looks once
    let Jazzy's MultiThreadedExecutor spin past its share, until students' programs got a
    shorter GIL switch interval (:mod:`autograder.sandbox.runner`; README, "Pacing")."""
    starved_poll_max: float = 0.004
    """Longest pause between two readings while every busy watched process waits for a
    CPU (its CPU time did not grow since the reading before): the pause doubles from
    ``poll_interval`` up to this, so that on a machine short of CPU the world's readings
    leave the cores to the processes it waits for."""
    max_tick: float = 2.0
    """Longest tick at RTF 0, in sim seconds."""
    receive_timeout: float = 0.5
    """Longest wait, once the watched processes are done, for the world's middleware to
    take in what they sent."""

    def __post_init__(self) -> None:
        if self.clock_hz <= 0:
            raise ValueError("clock_hz must be > 0")
        if self.cpu_budget < 0 or self.cpu_reserve < 0:
            raise ValueError("cpu_budget and cpu_reserve must be >= 0")


@dataclass(frozen=True)
class Tick:
    """One planned tick: its physics steps and the wall time it is given."""

    steps: int
    period: float
    adaptive: bool = False
    """Planned at RTF 0: its length follows how long ticks take."""


class Pacer:
    """Plans ticks, holds them for watched processes, and keeps their wall schedule.

    The world's thread loops: ``tick = next_tick()`` (None once stopped) with
    :attr:`condition` held, runs and publishes ``tick.steps`` steps, calls
    :meth:`note_tick`, releases the condition, then calls :meth:`pace` ``(tick)``.
    """

    def __init__(self, dt: float, real_time_factor: float = 1.0,
                 policy: PacingPolicy | None = None, *, clock: Clock | None = None,
                 read_process: ProcessReader = read_process_state,
                 receiving: Callable[[], bool] | None = None,
                 condition: threading.Condition | None = None) -> None:
        if real_time_factor < 0:
            raise ValueError("real_time_factor must be >= 0")
        self.dt = dt
        self.policy = policy or PacingPolicy()
        self.condition = condition or threading.Condition(threading.RLock())
        self._clock: Clock = clock or SystemClock()
        self._read = read_process
        # True while the world's middleware still takes messages in (None: never waited for).
        self._receiving = receiving
        self._rtf = real_time_factor
        self._adaptive_tick = 1.0 / self.policy.clock_hz
        self._running = True
        self._paused = False
        self._start: float | None = None  # wall time the coming tick's period began
        self._pids: set[int] = set()
        # (wall time, sim time) after each of the last ticks, for effective_rtf
        self._window: collections.deque[tuple[float, float]] = collections.deque(maxlen=100)
        self.counts: collections.Counter[HoldOutcome] = collections.Counter()
        self.longest_hold = 0.0  # wall seconds of the longest hold for watched processes
        # Wall seconds, summed, that holds ran past their tick's deadline: what a busy
        # watched process cost in wall time (a hold within the tick's period costs none).
        self.held_seconds = 0.0
        # Ticks held because a process was idle but had not heard the tick yet.
        self.late_deliveries = 0
        # Holds in which a process used more than cpu_budget, drawing on its reserve.
        self.bursts = 0
        # Holds that, the processes done, waited for the world to take in what they sent.
        self.receipts_awaited = 0
        self._reserve: dict[int, float] = {}  # CPU seconds each watched process has banked
        self._before: dict[int, int] = {}  # CPU ns of each watched process before a tick
        self._heard: set[int] = set()  # those seen to hear the last tick during its hold
        self._listening: set[int] = set()  # those that heard the tick before
        self._closing: set[int] = set()  # those being stopped: never waited for to hear

    # -- run state ------------------------------------------------------------------
    @property
    def paused(self) -> bool:
        return self._paused

    def pause(self) -> None:
        """No tick starts after this returns (ticks run under :attr:`condition`)."""
        with self.condition:
            self._paused = True

    def resume(self) -> None:
        with self.condition:
            self._paused = False
            self._window.clear()
            self.condition.notify_all()

    @contextlib.contextmanager
    def held(self) -> Iterator[None]:
        """No tick goes inside the block; afterwards ticks go again, unless paused before."""
        with self.condition:
            was_paused, self._paused = self._paused, True
        try:
            yield
        finally:
            if not was_paused:
                self.resume()

    def stop(self) -> None:
        """Make :meth:`next_tick` return None, now if it is waiting."""
        with self.condition:
            self._running = False
            self.condition.notify_all()

    # -- settings -------------------------------------------------------------------
    @property
    def real_time_factor(self) -> float:
        return self._rtf

    def set_real_time_factor(self, rtf: float) -> None:
        """Sim seconds per wall second; 0 runs as fast as the graph keeps up."""
        if rtf < 0:
            raise ValueError("real_time_factor must be >= 0")
        with self.condition:
            self._rtf = rtf
            self._window.clear()

    def watch(self, pid: int | None) -> None:
        """Also hold ticks while process ``pid`` has work (None: watch nothing)."""
        with self.condition:
            if pid is None:
                self._pids.clear()
                self._listening.clear()
                self._closing.clear()
                self._reserve.clear()
            else:
                self._pids.add(pid)
                self._listening.add(pid)
                self._closing.discard(pid)
                self._reserve.setdefault(pid, 0.0)
            self._window.clear()

    def unwatch(self, pid: int) -> None:
        with self.condition:
            self._pids.discard(pid)
            self._listening.discard(pid)
            self._closing.discard(pid)
            self._reserve.pop(pid, None)

    def closing(self, pid: int) -> None:
        """Process ``pid`` is being stopped: hold ticks while it has work, as before, but
        no longer wait for it to hear them (its node is going away)."""
        with self.condition:
            self._closing.add(pid)
            self._listening.discard(pid)

    def about_to_publish(self) -> None:
        """Read the watched processes' CPU time just before a tick goes out: a process
        whose CPU time grows from here on has heard it.  Also judge, over the whole time
        since the tick before, which of them heard that one: the next hold waits for
        those to hear this tick (call with :attr:`condition` held)."""
        states = {pid: self._read(pid) for pid in self._pids}
        for pid, state in states.items():
            if pid not in self._before:
                continue
            if pid in self._closing:
                continue
            if (pid in self._heard or not state.exists or state.busy
                    or state.cpu_ns > self._before[pid]):
                self._listening.add(pid)
            else:
                self._listening.discard(pid)
        self._before = {pid: state.cpu_ns for pid, state in states.items()}
        self._heard = set()

    # -- measuring ------------------------------------------------------------------
    def note_tick(self, sim_time: float) -> None:
        """A tick that ends at ``sim_time`` was just published."""
        self._window.append((self._clock.monotonic(), sim_time))

    def forget_rate(self) -> None:
        """Start measuring :attr:`effective_rtf` afresh (sim time jumped)."""
        with self.condition:
            self._window.clear()

    @property
    def effective_rtf(self) -> float:
        """Measured sim seconds per wall second over the last ticks (0 before two)."""
        with self.condition:
            if len(self._window) < 2:
                return 0.0
            (w0, s0), (w1, s1) = self._window[0], self._window[-1]
        return (s1 - s0) / (w1 - w0) if w1 > w0 else 0.0

    # -- scheduling -----------------------------------------------------------------
    def next_tick(self) -> Tick | None:
        """Wait while paused, then plan the next tick; None once stopped.

        Call it with :attr:`condition` held and run the tick before releasing it, so that
        a pause cannot slip in between.
        """
        with self.condition:
            if self._start is None:
                self._start = self._clock.monotonic()
            if self._running and self._paused:
                self._clock.wait(self.condition, lambda: not (self._running and self._paused))
                self._start = self._clock.monotonic()  # the schedule starts afresh
            if not self._running:
                return None
            return self._plan(self._rtf)

    def _plan(self, rtf: float) -> Tick:
        if rtf > 0:
            # The fewest whole steps of at least rtf / clock_hz: rounding down would give
            # ticks shorter than 1 / clock_hz of wall time, above the cap.
            exact = rtf / self.policy.clock_hz / self.dt
            steps = max(1, math.ceil(exact - 1e-9 * exact))
            return Tick(steps, steps * self.dt / rtf)
        steps = max(1, round(self._adaptive_tick / self.dt))
        return Tick(steps, 1.0 / self.policy.clock_hz, adaptive=True)

    def pace(self, tick: Tick) -> None:
        """After ``tick`` was published: hold for watched processes, then wait for the
        tick's wall deadline (no catch-up if it has passed)."""
        clock = self._clock
        started = self._start if self._start is not None else clock.monotonic()
        published = clock.monotonic()
        deadline = started + tick.period
        self._hold(published, deadline)
        now = clock.monotonic()
        if tick.adaptive and now > started:
            self._adapt(tick.period, now - started)
        if now < deadline:
            clock.sleep(deadline - now)
            self._start = deadline  # on schedule: keep it exact
        else:
            self._start = now  # late: no catch-up burst, sim time just runs slower

    def _adapt(self, period: float, took: float) -> None:
        """At RTF 0, scale the tick so that its work fills ``period`` of wall time (at most
        doubling or halving at once, so one odd tick does not swing it)."""
        ratio = min(2.0, max(0.5, period / took))
        self._adaptive_tick = min(self.policy.max_tick,
                                  max(self.dt, self._adaptive_tick * ratio))

    def _hold(self, published: float, deadline: float) -> None:
        """Hold until every watched process has heard the tick and is idle or has had its
        CPU share, or the cap.

        A process that keeps computing is let go once it has used ``cpu_budget`` seconds of
        CPU since the tick and whatever it has in reserve (it is busy, not slow); one that
        is runnable but gets no CPU (a busy machine) holds the world back, up to
        ``hold_cap`` of wall time; one that is idle but has not heard the tick is waited for
        up to ``hear_timeout``.  Then, up to ``receive_timeout``, the world's middleware
        must have taken in what they sent.
        """
        with self.condition:
            pids = tuple(self._pids)
            before, listening = dict(self._before), set(self._listening)
            reserve = {pid: self._reserve.get(pid, 0.0) for pid in pids}
        if not pids:
            self.counts["free"] += 1
            return
        clock, policy = self._clock, self.policy
        first = min(published + policy.settle, deadline)
        now = clock.monotonic()
        if now < first:
            clock.sleep(first - now)
        # Without a reading from before the tick (a process watched since), the budget
        # counts from now and the process counts as having heard the tick.
        baseline = {pid: before[pid] if pid in before else self._read(pid).cpu_ns
                    for pid in pids}
        heard = {pid: pid not in before for pid in pids}
        budget_ns = int(policy.cpu_budget * 1e9)
        share_ns = {pid: budget_ns + int(reserve[pid] * 1e9) for pid in pids}
        cap = published + policy.hold_cap
        deafness = published + policy.hear_timeout
        outcome: HoldOutcome = "cap"
        late = False
        receipt_cap: float | None = None  # set once the processes are done
        awaited = False
        states: dict[int, ProcessState] = {}
        pause = policy.poll_interval
        while (now := clock.monotonic()) < cap:
            previous, states = states, {pid: self._read(pid) for pid in pids}
            pause = (min(2 * pause, policy.starved_poll_max)
                     if _starved(previous, states) else policy.poll_interval)
            for pid, state in states.items():
                heard[pid] = heard[pid] or (not state.exists or state.busy
                                            or state.cpu_ns > baseline[pid])
            working = any(state.busy and state.cpu_ns - baseline[pid] < share_ns[pid]
                          for pid, state in states.items())
            waiting = [pid for pid in listening if pid in heard and not heard[pid]]
            if not working and waiting and now >= deafness:
                outcome = "unheard"
                break
            if not working and not waiting:
                if receipt_cap is None:
                    receipt_cap = now + policy.receive_timeout
                if self._receiving is None or now >= receipt_cap or not self._receiving():
                    outcome = "budget" if any(s.busy for s in states.values()) else "idle"
                    break
                awaited = True
            else:
                late = late or not working
            clock.sleep(pause)
        self.receipts_awaited += awaited
        burst = False
        with self.condition:
            self._heard = {pid for pid, yes in heard.items() if yes}
            for pid, state in states.items():
                used_ns = max(0, state.cpu_ns - baseline[pid])
                burst = burst or (used_ns > budget_ns and reserve[pid] > 0)
                if pid in self._reserve:  # not unwatched meanwhile
                    self._reserve[pid] = min(policy.cpu_reserve, max(
                        0.0, reserve[pid] + (budget_ns - used_ns) / 1e9))
        self.bursts += burst
        self.counts[outcome] += 1
        if late and outcome != "unheard":
            self.late_deliveries += 1
        ended = clock.monotonic()
        self.longest_hold = max(self.longest_hold, ended - published)
        self.held_seconds += max(0.0, ended - max(deadline, published))


def _starved(before: dict[int, ProcessState], now: dict[int, ProcessState]) -> bool:
    """Some process is busy, and none that is busy has run since the reading ``before``:
    they all wait for a CPU.  A thread's CPU time moves at the scheduler's events, so one
    that is running may read as waiting for a while; the pause then stays within
    ``starved_poll_max``."""
    busy = [pid for pid, state in now.items() if state.busy]
    return bool(busy) and all(pid in before and now[pid].cpu_ns == before[pid].cpu_ns
                              for pid in busy)
