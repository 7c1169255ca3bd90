"""When the world's next clock tick may go: the pacing, as a scheduler without ROS.

Simulation time must not run ahead of a student process that is slow to react, or
verdicts would depend on how busy the machine is.  The world advances in *clock ticks*
(a whole number of physics steps, then one ``/clock``); the :class:`Pacer` decides how
long each tick is and when the next one may go.  It reads time only through a
:class:`Clock` and the student's process only through a
:data:`~sim.procstate.ProcessReader`, so tests drive it with a fake clock and fake
processes.  The rules (why each was chosen, and what was measured: the contributors'
design notes, "Pacing"):

* **Tick length.**  At most ``clock_hz`` ticks per wall second (Jazzy's
  MultiThreadedExecutor keeps a sim-time timer exact at 20 Hz, not at 50).  At a real-time
  factor ``r > 0`` a tick is the fewest physics steps that make ``r / clock_hz`` of sim
  time; at ``r == 0`` its length adapts so that its work fills ``1 / clock_hz`` of wall
  time, up to ``max_tick``.
* **Wall deadline.**  A tick is given ``steps * dt / r`` wall seconds; a late tick moves
  the schedule (no catch-up burst), so sim time just runs slower.
* **Hold.**  With watched processes, the next tick also waits until each has *heard* the
  tick and is idle (two readings agreeing: one reading is thread after thread, not an
  instant), or has used its CPU share since the tick (``cpu_budget`` and what it banked
  in its reserve), so a process that waits for a CPU holds sim time back and one that
  busy-loops only slows it.  A process hears a tick when its own threads (not its
  middleware's, which take ``/clock`` in whether or not the node's executor wakes for
  it) use CPU or run after the tick went out; one that heard the tick before is waited
  for to hear this one, up to ``hear_timeout`` while the kernel holds no packet it has
  not yet delivered.
  Then the world's own middleware must have taken in what the processes sent, up to
  ``receive_timeout``.  ``hold_cap`` ends a hold, not counting the time in which every busy
  watched process waited for a CPU; ``hold_limit`` ends it whatever the machine.
* **Blocked.**  A process with a thread asleep in the kernel uninterruptibly (state
  ``D``: a page read in from disk, memory reclaimed) is not done: it goes on by itself.
  The hold waits for it as long as its ``blocked_reserve`` lasts, wall time taken from a
  store that starts full and is never paid back, so a process that stays blocked costs
  that much once, not every tick.
* **CPU reserve.**  Each watched process banks, up to ``cpu_reserve``, the part of
  ``cpu_budget`` it leaves unused in each tick, and a hold draws on that bank once the
  budget is used: a usually idle node may take a longer turn now and then (an executor
  catching up), while a busy loop banks nothing.
* **Held.**  Inside :meth:`Pacer.held` (a student's program starting) no tick goes;
  afterwards the schedule starts afresh from that moment.
* **Gate.**  A pacer made with ``gated=True`` (a grading's world) sends no tick until
  :meth:`Pacer.open_gate`: sim time stays at its start however long the machine takes
  to set the module up, so the student's node meets the same clock on any machine.

How each hold ended is counted (:attr:`Pacer.counts`: the results file's ``pacing``).
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
from dataclasses import dataclass, field
from typing import Literal, Protocol

from sim.procstate import ProcessReader, ProcessState, read_process_state

DEFAULT_CLOCK_HZ = 20.0
"""Most ``/clock`` messages per wall second: a 10 Hz sim-time timer stays exact."""
DEFAULT_CPU_BUDGET = 0.05
"""CPU seconds a busy student process gets after a tick before the world goes on."""

HoldOutcome = Literal["free", "idle", "budget", "unheard", "cap"]
"""How a tick's hold ended: nothing watched, all idle, CPU share used, a process that did
not hear the tick within ``hear_timeout``, or ``hold_cap``/``hold_limit``."""


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
    """Longest hold for watched processes, from the tick's publication, not counting the
    time in which every busy one waited for a CPU (the machine's doing, not theirs)."""
    hold_limit: float = 10.0
    """Longest hold in wall time, however long the processes waited for a CPU."""
    settle: float = 0.001
    """Pause after publishing before the first look at the processes: a reading taken at
    once would often find them idle only because the messages had not reached them."""
    hear_timeout: float = 0.5
    """Longest wait, from the tick's publication, for a watched process to hear it, while
    the kernel holds no packet it has not yet delivered."""
    cpu_reserve: float = 2.0
    """Most CPU seconds a watched process may bank, beyond ``cpu_budget``, for a burst."""
    poll_interval: float = 0.0005
    """Pause between two readings of the watched processes while holding a tick: short,
    so that a node's executor is not left spinning past its share between two looks."""
    starved_poll_max: float = 0.004
    """Longest pause between two readings while every busy watched process waits for a
    CPU: the pause doubles from ``poll_interval`` up to this, leaving the cores to them."""
    max_tick: float = 2.0
    """Longest tick at RTF 0, in sim seconds."""
    receive_timeout: float = 0.5
    """Longest wait, once the watched processes are done, for the world's middleware to
    take in what they sent."""
    blocked_reserve: float = 1.0
    """Most wall seconds, over a watched process's whole life, that holds wait for it
    while a thread of it sleeps in the kernel uninterruptibly (state ``D``) and it is
    otherwise done."""

    def __post_init__(self) -> None:
        if self.clock_hz <= 0:
            raise ValueError("clock_hz must be > 0")
        if self.cpu_budget < 0 or self.cpu_reserve < 0 or self.blocked_reserve < 0:
            raise ValueError("cpu_budget, cpu_reserve and blocked_reserve must be >= 0")


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
                 delivering: Callable[[], bool] | None = None,
                 condition: threading.Condition | None = None,
                 gated: bool = False) -> None:
        if real_time_factor < 0:
            raise ValueError("real_time_factor must be >= 0")
        self.dt = dt
        self.policy = policy or PacingPolicy()
        self.condition = condition or threading.Condition(threading.RLock())
        self._clock: Clock = clock or SystemClock()
        self._read = read_process
        # True while the world's middleware still takes messages in (None: never waited for).
        self._receiving = receiving
        # True while the kernel holds received packets no socket has been handed yet: a
        # tick may still be on its way to a process (None: never).
        self._delivering = delivering
        self._rtf = real_time_factor
        self._adaptive_tick = 1.0 / self.policy.clock_hz
        self._running = True
        self._paused = False
        self._gated = gated  # no tick until open_gate (see the module's "Gate")
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
        # Holds that waited for a process blocked in the kernel (state D), from its store.
        self.blocked_waits = 0
        self._reserve: dict[int, float] = {}  # CPU seconds each watched process has banked
        self._blocked_left: dict[int, float] = {}  # wall s each may yet be waited for in D
        # Each watched process as read just before a tick went out.
        self._before: dict[int, ProcessState] = {}
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

    @property
    def gated(self) -> bool:
        """No tick has been let go yet (see :meth:`open_gate`)."""
        return self._gated

    def open_gate(self) -> None:
        """Let the ticks of a pacer made ``gated`` go (unless paused or held); once."""
        with self.condition:
            if self._gated:
                self._gated = False
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
                self._blocked_left.clear()
            else:
                self._pids.add(pid)
                self._listening.add(pid)
                self._closing.discard(pid)
                self._reserve.setdefault(pid, 0.0)
                self._blocked_left.setdefault(pid, self.policy.blocked_reserve)
            self._window.clear()

    @property
    def watched(self) -> tuple[int, ...]:
        """The processes ticks are held for."""
        with self.condition:
            return tuple(self._pids)

    def unwatch(self, pid: int) -> None:
        with self.condition:
            self._pids.discard(pid)
            self._listening.discard(pid)
            self._closing.discard(pid)
            self._reserve.pop(pid, None)
            self._blocked_left.pop(pid, None)

    def closing(self, pid: int) -> None:
        """Process ``pid`` is being stopped: hold ticks while it has work, as before, but
        no longer wait for it to hear them (its node is going away)."""
        with self.condition:
            self._closing.add(pid)
            self._listening.discard(pid)

    def about_to_publish(self) -> None:
        """Read the watched processes' CPU time just before a tick goes out: a process
        whose own threads use CPU from here on has heard it.  Also judge, over the whole time
        since the tick before, which of them heard that one: the next hold waits for
        those to hear this tick (call with :attr:`condition` held)."""
        states = {pid: self._read(pid) for pid in self._pids}
        for pid, state in states.items():
            if pid not in self._before:
                continue
            if pid in self._closing:
                continue
            blocked = state.own_blocked and self._blocked_left.get(pid, 0.0) > 0.0
            if (pid in self._heard or not state.exists or state.own_busy or blocked
                    or state.own_cpu_ns > self._before[pid].own_cpu_ns):
                self._listening.add(pid)
            else:
                self._listening.discard(pid)
        self._before = states
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
            if self._running and (self._paused or self._gated):
                self._clock.wait(self.condition, lambda: not (
                    self._running and (self._paused or self._gated)))
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
        CPU share, then until the world has taken in what they sent (see the module's
        docstring), and count how the hold ended."""
        hold = self._begin_hold(published, deadline)
        if hold is None:
            self.counts["free"] += 1
            return
        outcome = self._poll(hold)
        self._account(hold, outcome, deadline)

    def _begin_hold(self, published: float, deadline: float) -> _Hold | None:
        """The watched processes as the tick went out (None: none watched), after
        ``settle``."""
        with self.condition:
            pids = tuple(self._pids)
            before, listening = dict(self._before), frozenset(self._listening)
            reserve = {pid: self._reserve.get(pid, 0.0) for pid in pids}
            blocked_left = {pid: self._blocked_left.get(pid, 0.0) for pid in pids}
        if not pids:
            return None
        policy = self.policy
        first = min(published + policy.settle, deadline)
        now = self._clock.monotonic()
        if now < first:
            self._clock.sleep(first - now)
        # Without a reading from before the tick (a process watched since), the budget
        # counts from now and the process counts as having heard the tick.
        start = {pid: before[pid] if pid in before else self._read(pid) for pid in pids}
        baseline = {pid: state.cpu_ns for pid, state in start.items()}
        budget_ns = int(policy.cpu_budget * 1e9)
        return _Hold(published=published, baseline=baseline,
                     own_baseline={pid: state.own_cpu_ns for pid, state in start.items()},
                     reserve=reserve,
                     share_ns={pid: budget_ns + int(reserve[pid] * 1e9) for pid in pids},
                     heard={pid: pid not in before for pid in pids}, listening=listening,
                     cap=published + policy.hold_cap, blocked_left=blocked_left)

    def _poll(self, hold: _Hold) -> HoldOutcome:
        """Read the watched processes until the hold may end; how it ended."""
        clock, policy = self._clock, self.policy
        limit = hold.published + policy.hold_limit
        deafness = hold.published + policy.hear_timeout
        receipt_due: float | None = None  # set once the processes are done
        pause, then = policy.poll_interval, clock.monotonic()
        while (now := clock.monotonic()) < min(hold.cap, limit):
            if hold.read({pid: self._read(pid) for pid in hold.baseline}, now - then):
                hold.cap += now - then  # they all waited for a CPU since the last look
                pause = min(2 * pause, policy.starved_poll_max)
            else:
                pause = policy.poll_interval
            then = now
            if hold.working:
                pass  # its share, or hold_cap, ends this
            elif not hold.still:
                pass  # one reading showed them done: a second must agree
            elif hold.deaf:
                if now >= deafness and not self._in_flight():
                    return "unheard"
                hold.late = True
            else:
                if receipt_due is None:
                    receipt_due = now + policy.receive_timeout
                if self._receiving is None or now >= receipt_due or not self._receiving():
                    return "budget" if hold.busy else "idle"
                hold.awaited = True
            clock.sleep(pause)
        return "cap"

    def _in_flight(self) -> bool:
        return self._delivering is not None and self._delivering()

    def _account(self, hold: _Hold, outcome: HoldOutcome, deadline: float) -> None:
        """Bank what each process left of its budget, and count the hold."""
        budget_ns = int(self.policy.cpu_budget * 1e9)
        burst = False
        with self.condition:
            self._heard = {pid for pid, yes in hold.heard.items() if yes}
            for pid, used_ns in hold.used_ns().items():
                burst = burst or (used_ns > budget_ns and hold.reserve[pid] > 0)
                if pid in self._reserve:  # not unwatched meanwhile
                    self._reserve[pid] = min(self.policy.cpu_reserve, max(
                        0.0, hold.reserve[pid] + (budget_ns - used_ns) / 1e9))
            for pid, left in hold.blocked_left.items():
                if pid in self._blocked_left:
                    self._blocked_left[pid] = left
        self.bursts += burst
        self.receipts_awaited += hold.awaited
        self.blocked_waits += hold.blocked_wait
        self.counts[outcome] += 1
        if hold.late and outcome != "unheard":
            self.late_deliveries += 1
        ended = self._clock.monotonic()
        self.longest_hold = max(self.longest_hold, ended - hold.published)
        self.held_seconds += max(0.0, ended - max(deadline, hold.published))


@dataclass
class _Hold:
    """One tick's hold: what the watched processes had when it went out, what each may
    use, and what the readings since showed (:meth:`Pacer._poll` fills it in)."""

    published: float
    baseline: dict[int, int]  # CPU ns of each process when the tick went out
    own_baseline: dict[int, int]  # CPU ns of its own threads (not its middleware's) then
    reserve: dict[int, float]  # CPU seconds each had banked
    share_ns: dict[int, int]  # CPU ns each may use before the tick goes on without it
    heard: dict[int, bool]  # whether each has heard the tick
    listening: frozenset[int]  # those that heard the tick before: waited for to hear it
    cap: float  # when hold_cap ends the hold (pushed back while they wait for a CPU)
    # Wall seconds each may still be waited for while blocked in the kernel (state D).
    blocked_left: dict[int, float] = field(default_factory=dict)
    states: dict[int, ProcessState] = field(default_factory=dict)  # the last reading
    late: bool = False  # an idle process had not heard the tick yet
    awaited: bool = False  # the world's middleware was still taking messages in
    blocked_wait: bool = False  # a process was waited for while blocked in the kernel
    still: bool = False  # the last two readings agree that none of them works

    def read(self, states: dict[int, ProcessState], since: float = 0.0) -> bool:
        """Take a reading, ``since`` wall seconds after the last; True if every busy
        process waited for a CPU since the last."""
        previous, self.states = self.states, states
        for pid, state in states.items():
            self.heard[pid] = self.heard[pid] or (
                not state.exists or state.own_busy
                or (state.own_blocked and self._waited_for(pid))
                or state.own_cpu_ns > self.own_baseline[pid])
            was = previous.get(pid)
            if was is not None and was.blocked and not was.busy and self._waited_for(pid):
                # waited for only because it was blocked: that comes from its store
                self.blocked_left[pid] = max(0.0, self.blocked_left[pid] - since)
                self.blocked_wait = True
        # A reading of a process is one thread after another, not one instant: a thread
        # woken by another after we read it, the other gone to sleep before we read it,
        # reads idle.  It will have run, or be runnable, by the next reading.
        self.still = all(not state.exists or self._spent(pid) or (
            pid in previous and not previous[pid].busy and not state.busy
            and not ((state.blocked or previous[pid].blocked) and self._waited_for(pid))
            and previous[pid].cpu_ns == state.cpu_ns) for pid, state in states.items())
        return _starved(previous, states)

    def _waited_for(self, pid: int) -> bool:
        """Process ``pid``, if blocked in the kernel, is still waited for: its store of
        such waits is not used up."""
        return self.blocked_left.get(pid, 0.0) > 0.0

    def _spent(self, pid: int) -> bool:
        """Process ``pid`` has used its share since the tick (it is let go, busy or not)."""
        return self.states[pid].cpu_ns - self.baseline[pid] >= self.share_ns[pid]

    @property
    def working(self) -> bool:
        """Some process is busy and has not used its share."""
        return any(state.busy and state.cpu_ns - self.baseline[pid] < self.share_ns[pid]
                   for pid, state in self.states.items())

    @property
    def busy(self) -> bool:
        return any(state.busy for state in self.states.values())

    @property
    def deaf(self) -> bool:
        """Some process that heard the tick before has not heard this one yet."""
        return any(not self.heard[pid] for pid in self.listening if pid in self.heard)

    def used_ns(self) -> dict[int, int]:
        """CPU ns each process used since the tick, as last read."""
        return {pid: max(0, state.cpu_ns - self.baseline[pid])
                for pid, state in self.states.items()}


def _starved(before: dict[int, ProcessState], now: dict[int, ProcessState]) -> bool:
    """Some process is busy, and none that is busy has run since the reading ``before``:
    they all wait for a CPU.  A thread's CPU time moves at the scheduler's events, so one
    that is running may read as waiting for a while; the pause then stays within
    ``starved_poll_max``."""
    busy = [pid for pid, state in now.items() if state.busy]
    return bool(busy) and all(pid in before and now[pid].cpu_ns == before[pid].cpu_ns
                              for pid in busy)
