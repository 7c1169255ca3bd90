"""Reading a process's state from /proc: busy (running or runnable) and CPU time used."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator

import pytest

from sim.pacing import DEFAULT_CPU_BUDGET
from sim.procstate import (
    IDLE,
    Receiving,
    UsageTally,
    backlog,
    descendants,
    family_usage,
    process_busy,
    read_process_state,
    thread_busy,
)

WALL = 20.0

# Prints a line once it is in its loop, so the test knows it is spinning.
SPIN = [sys.executable, "-c", "print('spinning', flush=True)\nwhile True: pass"]


def _spinning() -> subprocess.Popen[str]:
    proc = subprocess.Popen(SPIN, stdout=subprocess.PIPE, text=True)
    assert proc.stdout is not None and proc.stdout.readline() == "spinning\n"
    return proc


def _poll(condition, timeout: float = WALL) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.01)
    return bool(condition())


@pytest.fixture
def spinner() -> Iterator[subprocess.Popen[str]]:
    proc = _spinning()
    try:
        yield proc
    finally:
        proc.kill()
        proc.wait()


def test_process_busy_reads_proc() -> None:
    assert process_busy(os.getpid())  # this thread is running right now
    assert not process_busy(2**22 + 12345)  # no such process
    assert read_process_state(2**22 + 12345) == IDLE


def test_a_thread_asleep_in_the_kernel_reads_blocked_not_busy(tmp_path) -> None:
    """State D (uninterruptible sleep: a page read in from disk, memory reclaimed) is
    neither idle nor busy: the pacing waits for it from a store of its own. A process
    whose ``posix_spawn`` child (glibc: clone with CLONE_VFORK) is stuck opening a FIFO no
    one writes waits in D until the child goes on."""
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    helper = subprocess.Popen([sys.executable, "-c", (
        "import os\n"
        f"os.posix_spawn('/bin/true', ['true'], {{}}, file_actions=[(os.POSIX_SPAWN_OPEN, 3, "
        f"{str(fifo)!r}, os.O_RDONLY, 0)])\n")])
    try:
        # Blocked in the vfork wait, once its child is there: not in a page read of its own
        # start-up, which a fresh machine's cold cache also shows as D (CI read one, then
        # found the helper running, 13 ms of CPU into its start).
        assert _poll(lambda: bool(descendants(helper.pid))
                     and read_process_state(helper.pid).blocked)
        state = read_process_state(helper.pid)
        assert state.blocked and state.own_blocked and not state.busy
    finally:
        try:  # the child's open returns: it execs, and its parent goes on
            os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
        except OSError:  # no one opened it: the helper never got that far
            helper.kill()
        helper.wait(timeout=WALL)
    assert helper.returncode == 0


def test_a_computing_process_is_busy_and_uses_cpu(spinner: subprocess.Popen[str]) -> None:
    start = read_process_state(spinner.pid)
    assert start.busy and start.cpu_ns > 0
    assert _poll(lambda: read_process_state(spinner.pid).cpu_ns > start.cpu_ns + 20_000_000)


def test_a_blocked_process_is_idle_and_uses_no_cpu() -> None:
    proc = subprocess.Popen([sys.executable, "-c", "import sys; sys.stdin.read()"],
                            stdin=subprocess.PIPE)
    try:
        assert _poll(lambda: not process_busy(proc.pid))  # once start-up is over
        start = read_process_state(proc.pid)
        samples = []
        for _ in range(10):  # a tenth of a second of samples
            samples.append(read_process_state(proc.pid))
            time.sleep(0.01)
        assert samples == [start] * 10  # not busy, and no CPU time used
    finally:
        proc.kill()
        proc.wait()


@pytest.mark.skipif(not hasattr(os, "sched_setaffinity"), reason="needs sched_setaffinity")
def test_a_starved_process_is_busy_but_gets_no_cpu() -> None:
    """Runnable without a CPU (a busy machine) reads busy, with CPU time nearly still: the
    pacing then holds the world for it (test_sim_pacing's starved process)."""
    hog, starved = _spinning(), _spinning()
    try:
        for proc in (hog, starved):  # both on CPU 0; the "student" at the lowest priority
            os.sched_setaffinity(proc.pid, {0})
        os.setpriority(os.PRIO_PROCESS, starved.pid, 19)
        start = read_process_state(starved.pid)
        samples = []
        for _ in range(50):  # half a second of samples
            samples.append(read_process_state(starved.pid))
            time.sleep(0.01)
        used = samples[-1].cpu_ns - start.cpu_ns
    finally:
        for proc in (hog, starved):
            proc.kill()
            proc.wait()
    assert all(s.busy for s in samples)
    # At this rate it would not use its CPU budget within the 2 s cap of a hold.
    assert used < DEFAULT_CPU_BUDGET * 1e9 / 4, used


def test_a_thread_of_ours_that_waits_for_a_cpu_reads_busy_and_one_that_sleeps_idle() -> None:
    """thread_busy: a thread of this process kept from the CPU (a crowded machine) reads
    busy in every reading, as the probe's executor must when it has messages to deliver;
    one blocked on an event reads idle, and a thread that is gone reads idle."""
    import hashlib

    stop, sleeping = threading.Event(), threading.Event()
    tids: dict[str, int] = {}
    started = threading.Barrier(3)

    def crunch() -> None:  # hashing releases the GIL: the thread stays runnable
        tids["crunching"] = threading.get_native_id()
        os.sched_setaffinity(0, {0})  # this thread only, beside the hog, at the lowest
        os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), 19)
        started.wait()
        block, digest = bytes(1 << 22), hashlib.sha256()
        while not stop.is_set():
            digest.update(block)

    def sleep() -> None:
        tids["waiting"] = threading.get_native_id()
        started.wait()
        sleeping.wait()

    hog = _spinning()
    os.sched_setaffinity(hog.pid, {0})
    cruncher, sleeper = threading.Thread(target=crunch), threading.Thread(target=sleep)
    cruncher.start()
    sleeper.start()
    try:
        started.wait(WALL)
        crunching, waiting = tids["crunching"], tids["waiting"]
        busy = []
        for _ in range(50):
            busy.append(thread_busy(crunching))
            time.sleep(0.01)
    finally:
        stop.set()
        cruncher.join()
        hog.kill()
        hog.wait()
    # Read once the cruncher is gone: starved while it held the GIL, it could keep the
    # sleeper waiting for the GIL on its way into its wait, woken every 5 ms to ask again.
    try:
        assert _poll(lambda: not thread_busy(waiting))  # in its wait: it stays there
        idle = []
        for _ in range(20):
            idle.append(not thread_busy(waiting))
            time.sleep(0.01)
    finally:
        sleeping.set()
        sleeper.join()
    assert all(busy), busy
    assert all(idle), idle
    assert not thread_busy(crunching)  # gone


# A process whose thread count changes on command: a line "+" starts a thread that blocks,
# "-" ends the newest; each answers with the count of threads it now has.
THREADS = [sys.executable, "-c", """\
import sys, threading
stops = []
for line in sys.stdin:
    if line.strip() == "+":
        stop = threading.Event()
        thread = threading.Thread(target=stop.wait)
        thread.start()
        stops.append((stop, thread))
    elif line.strip() == "-":
        stop, thread = stops.pop()
        stop.set()
        thread.join()
    print(threading.active_count(), flush=True)
for stop, _ in stops:
    stop.set()
"""]


def _open_fds() -> int:
    return len(os.listdir("/proc/self/fd"))


def _name_thread(tid: int, name: str) -> None:
    with open(f"/proc/self/task/{tid}/comm", "w") as fh:  # a process may rename its own
        fh.write(name)


def test_receiving_follows_the_receive_threads_by_name(tmp_path) -> None:
    """A thread named as Fast DDS names its receive threads counts while it runs; it and
    a thread of another name do not while they wait."""
    import threading

    quiet = tmp_path / "softnet_stat"
    quiet.write_text("00000001 " * 11 + "00000000 00000000 00000000 00000000\n")  # no backlog
    stop, go = threading.Event(), threading.Event()
    tids: list[int] = []

    def receiver() -> None:
        tids.append(threading.get_native_id())
        go.wait()
        while not stop.is_set():  # "receiving": runs until told to stop
            pass

    def other() -> None:
        tids.append(threading.get_native_id())
        stop.wait()

    threads = [threading.Thread(target=receiver), threading.Thread(target=other)]
    for thread in threads:
        thread.start()
    receiving = Receiving(softnet=str(quiet))
    try:
        assert _poll(lambda: len(tids) == 2)
        _name_thread(tids[0], "dds.udp.7411")
        _name_thread(tids[1], "dds.shm.wdog")
        assert _poll(lambda: not receiving())  # named, but waiting
        go.set()
        assert _poll(receiving)
        stop.set()
        threads[0].join()
        assert _poll(lambda: not receiving())
    finally:
        go.set()
        stop.set()
        for thread in threads:
            thread.join()
        receiving.close()
    assert not receiving()  # closed: nothing to wait for


def test_receiving_counts_packets_the_kernel_still_holds(tmp_path) -> None:
    """softnet_stat's backlog column (Linux 5.10+), summed over CPUs; older kernels'
    shorter rows say nothing, so they count as none."""
    stat = tmp_path / "softnet_stat"
    row = "00dca0bc 00000000 00000004 " + "00000000 " * 8 + "{backlog:08x} {cpu:08x}"
    stat.write_text("\n".join([row.format(backlog=0, cpu=0) + " 00000000 00000000",
                               row.format(backlog=3, cpu=1) + " 00000003 00000000"]) + "\n")
    assert backlog(str(stat)) == 3
    assert Receiving(names=(), softnet=str(stat))()
    stat.write_text("00dca0bc 00000000 00000004" + " 00000000" * 8 + "\n")  # Linux 5.4
    assert backlog(str(stat)) == 0
    assert backlog(str(tmp_path / "missing")) == 0
    assert backlog() >= 0  # this machine's


# Starts a thread that spins, says so, and ends it on a line from the test; repeats.
THREADS = [sys.executable, "-c", """
import sys, threading
while sys.stdin.readline():
    stop = threading.Event()
    def spin():
        while not stop.is_set():
            pass
    thread = threading.Thread(target=spin)
    thread.start()
    print("spinning", flush=True)
    sys.stdin.readline()
    stop.set()
    thread.join()
    print("ended", flush=True)
"""]


def _open_fds() -> int:
    return len(os.listdir("/proc/self/fd"))


def test_kept_files_follow_threads_that_come_and_go_and_close_with_the_process() -> None:
    before = _open_fds()
    proc = subprocess.Popen(THREADS, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            text=True)
    assert proc.stdin is not None and proc.stdout is not None
    try:
        for _round in range(3):  # a new thread each round, perhaps under an old number
            assert _poll(lambda: not read_process_state(proc.pid).busy)  # the main thread waits
            proc.stdin.write("go\n")
            proc.stdin.flush()
            assert proc.stdout.readline() == "spinning\n"
            assert _poll(lambda: read_process_state(proc.pid).busy)  # the new thread
            proc.stdin.write("stop\n")
            proc.stdin.flush()
            assert proc.stdout.readline() == "ended\n"
    finally:
        proc.stdin.close()
        proc.wait()
        proc.stdout.close()
    assert read_process_state(proc.pid) == IDLE  # gone: its files are closed
    assert _open_fds() == before


# A thread named as Fast DDS names its receive threads spins; the main thread waits for
# "go", then spins too.
# The middleware's thread spins in C without the GIL (pbkdf2_hmac releases it), as Fast
# DDS's do: a Python loop would hold the GIL, and the main thread, waiting for it on its
# way into readline, would read idle once and then use CPU.
MIDDLEWARE_SPINS = [sys.executable, "-c", """
import hashlib, sys, threading
named = threading.Event()
def middleware():
    with open(f"/proc/self/task/{threading.get_native_id()}/comm", "w") as fh:
        fh.write("dds.udp.7411")
    named.set()
    while True:
        hashlib.pbkdf2_hmac("sha256", b"x", b"y", 10**6)
threading.Thread(target=middleware, daemon=True).start()
named.wait()
print("spinning", flush=True)
sys.stdin.readline()
while True:
    pass
"""]


def test_a_programs_own_threads_are_read_apart_from_its_middlewares() -> None:
    """What Fast DDS's threads (``dds.*``) do counts in busy and CPU time, but not in the
    program's own: a node's middleware taking a tick in is not its executor hearing it."""
    proc = subprocess.Popen(MIDDLEWARE_SPINS, stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True)
    assert proc.stdin is not None and proc.stdout is not None
    try:
        assert proc.stdout.readline() == "spinning\n"
        readings = [read_process_state(proc.pid)]

        def main_thread_waits() -> bool:  # it may still be on its way into readline
            readings.append(read_process_state(proc.pid))
            before, now = readings[-2:]
            return not now.own_busy and now.own_cpu_ns == before.own_cpu_ns

        assert _poll(main_thread_waits)
        first = readings[-1]
        assert _poll(lambda: read_process_state(proc.pid).cpu_ns > first.cpu_ns + 10**7)
        middleware_only = read_process_state(proc.pid)
        assert middleware_only.busy and not middleware_only.own_busy
        assert middleware_only.own_cpu_ns == first.own_cpu_ns  # the main thread waits
        proc.stdin.write("go\n")
        proc.stdin.flush()
        assert _poll(lambda: read_process_state(proc.pid).own_busy)
        assert _poll(lambda: read_process_state(proc.pid).own_cpu_ns
                     > middleware_only.own_cpu_ns + 10**7)
    finally:
        proc.kill()
        proc.wait()
        proc.stdin.close()
        proc.stdout.close()


def test_family_usage_keys_each_process_by_pid_and_start():
    spinner = _spinning()
    try:
        usage = family_usage([spinner.pid, os.getpid(), 2**22 + 7])  # the last: no such pid
        assert {pid for pid, _start in usage} == {spinner.pid, os.getpid()}
        cpu, waited = usage[next(k for k in usage if k[0] == spinner.pid)]
        assert cpu > 0 and waited >= 0
    finally:
        spinner.kill()
        spinner.wait()


def test_a_tally_counts_a_process_from_its_first_reading_and_one_born_later_whole():
    procs = [_spinning()]
    family = [procs[0].pid]
    tally = UsageTally(lambda: family, every=0.0)
    try:
        tally.read()
        assert tally.cpu_seconds == 0  # what it ran before the span is not counted
        procs.append(_spinning())
        family.append(procs[1].pid)
        assert _poll(lambda: (tally.read(), tally.cpu_seconds)[1] >= 0.4)
        # The young one counts from 0 (its start, inside the span), the old one from the
        # first reading: stopped, so its CPU time holds still, the young one's whole CPU
        # time is in the sum.
        os.kill(procs[1].pid, signal.SIGSTOP)
        tally.read()
        young = sum(cpu for cpu, _w in family_usage([procs[1].pid]).values()) / 1e9
        assert young > 0.05 and tally.cpu_seconds >= young
        assert tally.span_seconds > 0
    finally:
        for proc in procs:
            proc.kill()
            proc.wait()


def test_a_tally_reads_nothing_before_it_is_due():
    calls = []
    now = [100.0]
    tally = UsageTally(lambda: calls.append(1) or [], every=0.25, clock=lambda: now[0])
    tally.read_if_due()
    assert calls == [] and tally.span_seconds == 0.0
    now[0] += 0.3
    tally.read_if_due()
    assert calls == [1]
    now[0] += 1.0
    assert tally.span_seconds == 1.0
