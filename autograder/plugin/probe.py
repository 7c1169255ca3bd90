"""The grader's probe: a node that talks to the student's node the way another node would.

It publishes, records what it receives stamped with simulation time, calls services and
sets parameters.  Every wait has a deadline in simulation time and a wall-time cap, so
a stalled world or a hung node ends a test with a message instead of hanging it.  Taps
(:meth:`Probe.add_tap`, a bag recorder) get what it receives and publishes, except what
the world already hands them.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterable, Iterator
from typing import Any, Generic, TypeVar

from rcl_interfaces.msg import SetParametersResult
from rcl_interfaces.srv import GetParameters, SetParameters
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter, parameter_value_to_python
from rclpy.qos import QoSProfile, ReliabilityPolicy

from autograder.core.errors import GraderError, StudentFailure
from autograder.i18n import _
from autograder.plugin.msgtypes import CHECK_EVERY, TypeWatch, watch_world_cmd_vel
from sim.bag import Tap
from sim.msgdefs import type_name
from sim.procstate import UsageTally, thread_busy

M = TypeVar("M")

PROBE_NODE_NAME = "autograder_probe"
# The world's node, as the grader names it (sim.bridge.SimBridge's node_name).
WORLD_NODE_NAME = "sim_world"
# Names only the grader's own nodes may carry (the tampering guard checks them).
GRADER_NODES = (PROBE_NODE_NAME, WORLD_NODE_NAME)
# A wait that runs out holds the world while the probe's executor still has messages to
# hand over, this long at most, looking this often (wall seconds).
DELIVERY_LIMIT = 1.0
DELIVERY_POLL = 0.005


class Inbox(Generic[M]):
    """Messages received on one topic, each with the simulation time it arrived at."""

    def __init__(self, topic: str) -> None:
        self.topic = topic
        self._items: list[tuple[float, M]] = []
        # Each message's DDS source timestamp (wall seconds; None: not known), beside
        # _items: how a stream's intervals look in wall time tells which clock timed it.
        self._sent: list[float | None] = []
        self._lock = threading.Condition()
        self._arrivals = 0  # counts dropped messages too: a flood is not quiet
        self.subscription: Any = None
        self.dropped = 0

    def publisher_count(self) -> int:
        """Publishers matched with this inbox's subscription (0 until discovery)."""
        return self.subscription.get_publisher_count() if self.subscription else 0

    # A flood must not exhaust the grader's memory: past this, messages are only counted.
    LIMIT = 100_000

    def add(self, stamp: float, message: M, sent: float | None = None) -> None:
        with self._lock:
            if len(self._items) < self.LIMIT:
                self._items.append((stamp, message))
                self._sent.append(sent)
            else:
                self.dropped += 1
            self._arrivals += 1
            self._lock.notify_all()

    def wait_until(self, condition: Callable[[], bool], wall_timeout: float) -> bool:
        """Wait, in wall time, until ``condition()`` holds after some message arrived
        (checked at once, then on each arrival); False at the deadline.

        For when simulation time is no measure, e.g. after the node's process ended.
        """
        end = time.monotonic() + wall_timeout
        with self._lock:
            while not condition():
                left = end - time.monotonic()
                if left <= 0:
                    return False
                self._lock.wait(left)
            return True

    def wait_quiet(self, quiet: float, limit: float,
                   delivering: Callable[[], bool] | None = None) -> bool:
        """Wait until no message has arrived for ``quiet`` wall seconds and, where given,
        ``delivering()`` (what hands this inbox its messages still has work) read False
        twice at its end; False if that did not happen within ``limit`` seconds.

        Without ``delivering``, quiet only means that nothing came: on a crowded machine
        the thread that delivers may just have had no CPU for that long."""
        end = time.monotonic() + limit
        while True:
            with self._lock:
                seen, now = self._arrivals, time.monotonic()
                if now >= end:
                    return False
                self._lock.wait(min(quiet, end - now))
                if self._arrivals != seen or time.monotonic() - now < quiet - 1e-3:
                    continue
            # Read outside the lock: a delivering thread waiting for it would read idle.
            # Twice: one reading is one thread after another, not one instant.
            if delivering is None or not (delivering() or delivering()):
                with self._lock:
                    if self._arrivals == seen:
                        return True

    @property
    def items(self) -> list[tuple[float, M]]:
        with self._lock:
            return list(self._items)

    @property
    def messages(self) -> list[M]:
        return [m for _, m in self.items]

    @property
    def times(self) -> list[float]:
        return [t for t, _ in self.items]

    @property
    def sent(self) -> list[tuple[float, float | None]]:
        """(sim stamp, wall time it was sent at) for each message, in arrival order."""
        with self._lock:
            return [(t, w) for (t, _m), w in zip(self._items, self._sent, strict=True)]

    def since(self, stamp: float) -> list[M]:
        return [m for t, m in self.items if t >= stamp]

    def __len__(self) -> int:
        with self._lock:
            return len(self._items)

    def __iter__(self) -> Iterator[M]:
        """The messages so far, in arrival order (``for msg in inbox``: a snapshot, as
        ``inbox.messages`` is)."""
        return iter(self.messages)

    def clear(self) -> None:
        with self._lock:
            self._items.clear()
            self._sent.clear()


def kept_busy(cpu: float, waited: float, wall: float) -> bool:
    """Whether the watched program (its node, and every process it started) kept the
    machine busy over ``wall`` seconds, from the CPU seconds it used and the seconds its
    threads waited for a CPU meanwhile (summed): it ran for at least half of the time it
    was not kept waiting, and at least BUSY_CPU_SECONDS.  A busy loop is running or queued
    for a CPU all the time, so however small its share of a loaded machine, it runs
    whenever it is out of the queue (no share of the wall time is asked: a crowded machine
    gives a spinning executor little of it); a node that only reacts to ticks sleeps
    through a stalled world, so its CPU is a small part of its time out of the queue.
    Children that spin to starve the world count as the program's.  Below that the
    machine is to blame."""
    return cpu >= max(BUSY_CPU_SECONDS, 0.5 * (wall - waited))


def stall_cap(sim_timeout: float, pace: float) -> float:
    """Wall seconds after which a wait for ``sim_timeout`` of simulation time counts as a
    stalled world: STALL_FACTOR times the wall time the wait takes at ``pace`` (sim seconds
    per wall second; 0: as fast as the graph keeps up) or at real time, whichever is
    longer, and at least MIN_STALL_SECONDS. A pace below real time stretches the cap with
    it: at half pace a wait of 3 s takes 6 s before any hold, and four times that leaves
    the holds of a loaded machine as much room as at real time."""
    slowest = sim_timeout / pace if 0.0 < pace < 1.0 else sim_timeout
    return max(MIN_STALL_SECONDS, STALL_FACTOR * slowest)


STALL_FACTOR = 4.0
"""How many times the wall time a wait takes at its pace (or at real time, if faster) a
world may take before the wait counts as stalled."""
MIN_STALL_SECONDS = 10.0
"""The least wall time any wait is given before it counts as stalled."""
BUSY_CPU_SECONDS = 0.5
"""The least CPU a node must have used in a stalled wait to be what stalled it."""
TALLY_EVERY = 0.25
"""Wall seconds between readings of the program's processes during a wait."""


class Probe:
    """A node in the grader's process, on the same graph as the student's node."""

    def __init__(self, context: Context, world: Any, name: str = PROBE_NODE_NAME) -> None:
        self.world = world
        # No parameter services: a student's program must not change the grader's
        # parameters (use_sim_time); ours are set here, in-process.
        self.node = Node(name, context=context, start_parameter_services=False,
                         parameter_overrides=[Parameter("use_sim_time", value=True)])
        self._executor = SingleThreadedExecutor(context=context)
        self._executor.add_node(self.node)
        self._publishers: dict[str, Any] = {}
        self._taps: list[Tap] = []
        self._subscribed: set[str] = set()
        # Endpoints of the student's whose type never matches the grader's (msgtypes.py).
        self.types = TypeWatch(self.node, GRADER_NODES)
        watch_world_cmd_vel(self.types, getattr(world, "cmd_vel_type", None))
        self.node.create_timer(CHECK_EVERY, self.types.check)  # in simulation time
        self._thread = threading.Thread(target=self._spin, daemon=True, name="probe-executor")
        self._thread.start()

    def add_tap(self, tap: Tap) -> None:
        """Hand ``tap(topic, type name, message, sim time)`` each message this probe receives
        or publishes, but not twice: not what it receives on the world's own topics (the
        world's taps see those), nor what it publishes on a topic that the world or this
        probe subscribes to (seen again on arrival)."""
        self._taps.append(tap)

    def _tap(self, topic: str, message: Any, stamp: float) -> None:
        for tap in self._taps:
            tap(topic, type_name(type(message)), message, stamp)

    def _received(self, topic: str, inbox: Inbox[Any], stamp: float, message: Any,
                  sent: float | None = None) -> None:
        inbox.add(stamp, message, sent)
        world = (*getattr(self.world, "PUBLISHES", ()), *getattr(self.world, "SUBSCRIBES", ()))
        if topic not in world:
            self._tap(topic, message, stamp)

    def _spin(self) -> None:
        try:
            self._executor.spin()
        except Exception:  # the context shutting down ends the spin
            pass

    def close(self) -> None:
        self.types.check()  # a last look while the node is on the graph
        self.types.close()
        self._executor.shutdown(timeout_sec=2.0)
        self.node.destroy_node()
        self._thread.join(2.0)

    @property
    def now(self) -> float:
        """Simulation time in seconds."""
        return float(self.world.now)

    # -- waiting -----------------------------------------------------------------------
    def wait_for(self, condition: Callable[[], bool], sim_timeout: float,
                 wall_timeout: float | None = None) -> bool:
        """True once ``condition()`` holds, False when ``sim_timeout`` of sim time passed
        and it did not hold once the probe had taken in what reached it by then.

        The wall cap (default: :func:`stall_cap` at the world's pace as the wait begins)
        only ends waits on a world that stopped advancing; it raises, as that is no verdict
        on a sim-time condition: the student's failure if its node kept the CPU busy
        meanwhile (the world holds ticks for it), else the grader's (:func:`kept_busy`).
        """
        wall = wall_timeout if wall_timeout is not None else stall_cap(
            sim_timeout, float(getattr(self.world, "real_time_factor", 0.0)))
        start = self.now

        def elapsed() -> bool:  # sim time is steps * dt: 12.4 - 12.3 may be 0.0999...
            return self.now - start >= sim_timeout - 1e-9

        if condition():
            return True
        # What the program's processes use during the wait, read every TALLY_EVERY.
        family = getattr(self.world, "watched_family", None)
        tally = UsageTally(family, TALLY_EVERY) if family is not None else None
        began = time.monotonic()

        def done_waiting() -> bool:
            if tally is not None:
                tally.read_if_due()
            return condition() or elapsed()

        done = self.world.wait_for(done_waiting, sim_timeout=sim_timeout, wall_timeout=wall)
        if condition():
            return True
        if not done and not elapsed():
            took = time.monotonic() - began
            # How far it got says how stalled it was: not at all, or only too slowly.
            progress = {"seconds": took, "advanced": max(0.0, self.now - start),
                        "needed": sim_timeout}
            if tally is not None:
                tally.read()
            if tally is not None and not kept_busy(tally.cpu_seconds, tally.waited_seconds,
                                                   tally.span_seconds):
                raise GraderError(
                    _("In {seconds:.0f} s of wall time the simulation advanced {advanced:.2f} s "
                      "of the {needed:.1f} s this wait needed, and the node was not what kept "
                      "it busy: the machine was too busy to grade. Grade again on a quieter "
                      "machine.").format(**progress))
            raise StudentFailure(
                _("In {seconds:.0f} s of wall time the simulation advanced {advanced:.2f} s of "
                  "the {needed:.1f} s this wait needed: the node kept the machine too "
                  "busy.").format(**progress),
                _("Look for busy loops; use timers and callbacks instead of while loops."))
        return self._once_delivered(condition)

    def _once_delivered(self, condition: Callable[[], bool]) -> bool:
        """``condition()`` once what this process took in by now has reached the probe's
        callbacks. The world waits for the node, not for this probe: on a crowded machine a
        message sent in time can still be queued for the probe's executor when the
        simulation time runs out, so the world is held while that executor has work (up to
        :data:`DELIVERY_LIMIT` of wall time)."""
        if not (self.delivering() or self.delivering()):  # twice: one reading is not an instant
            return condition()
        with self.world.held():
            end = time.monotonic() + DELIVERY_LIMIT
            while not condition() and time.monotonic() < end and (
                    self.delivering() or self.delivering()):
                time.sleep(DELIVERY_POLL)
            return condition()

    def settle(self, inbox: Inbox[Any], quiet: float = 0.05, limit: float = 1.0) -> None:
        """Hold simulation time until nothing new has reached ``inbox`` for ``quiet`` wall
        seconds and nothing is on its way in (:meth:`delivering`), at most ``limit``: then
        it holds all the node sent so far, however late a busy machine delivers it (the
        world waits for the node, not for the probe)."""
        with self.world.held():
            inbox.wait_quiet(quiet, limit, self.delivering)

    def delivering(self) -> bool:
        """Whether messages may still be on their way into this probe's inboxes: its
        executor's thread runs or waits for a CPU (a crowded machine may leave it queued
        longer than any quiet spell), or this process's middleware is taking messages in."""
        tid = self._thread.native_id
        if tid is not None and self._thread.is_alive() and thread_busy(tid):
            return True
        receiving = getattr(self.world, "receiving", None)
        return bool(receiving is not None and receiving())

    def wait_sim(self, seconds: float) -> None:
        """Let ``seconds`` of simulation time pass (the world keeps running meanwhile)."""
        end = self.now + seconds
        self.wait_for(lambda: self.now >= end, seconds + 1.0)

    # -- topics ------------------------------------------------------------------------
    def subscribe(self, msg_type: type[M], topic: str, depth: int = 1000,
                  stamp: str = "received") -> Inbox[M]:
        """Record ``topic``; each message stamped with the sim time it arrived at, or with
        ``stamp="published"`` the sim time it was sent at (from its DDS source timestamp,
        so a probe slow to receive under load does not stamp it late)."""
        inbox: Inbox[M] = Inbox(topic)
        qos = QoSProfile(depth=depth, reliability=ReliabilityPolicy.RELIABLE)
        sent_at = getattr(self.world, "sim_time_at", None)
        name = self.node.resolve_topic_name(topic)
        self._subscribed.add(name)
        if stamp == "published" and sent_at is not None:
            def record(message: Any, info: dict[str, Any]) -> None:
                source = info.get("source_timestamp") if isinstance(info, dict) else None
                at = min(sent_at(source), self.now) if source else self.now
                self._received(name, inbox, at, message, source / 1e9 if source else None)

            inbox.subscription = self.node.create_subscription(msg_type, topic, record, qos)
        else:
            inbox.subscription = self.node.create_subscription(
                msg_type, topic, lambda m: self._received(name, inbox, self.now, m), qos)
        self.types.takes(inbox.subscription.topic_name, type_name(msg_type))
        return inbox

    def publish(self, msg_type: type, topic: str, message: Any) -> None:
        publisher = self._publisher(msg_type, topic)
        publisher.publish(message)
        name = publisher.topic_name
        if name not in (*getattr(self.world, "SUBSCRIBES", ()), *self._subscribed):
            self._tap(name, message, self.now)

    def wait_for_subscriber(self, msg_type: type, topic: str, sim_timeout: float = 5.0) -> bool:
        """Wait until someone subscribes to ``topic`` (so our first message is not lost)."""
        publisher = self._publisher(msg_type, topic)
        return self.wait_for(lambda: publisher.get_subscription_count() > 0, sim_timeout)

    def _publisher(self, msg_type: type, topic: str) -> Any:
        publisher = self._publishers.get(topic)
        if publisher is None:
            publisher = self.node.create_publisher(msg_type, topic, 10)
            self._publishers[topic] = publisher
            self.types.sends(publisher.topic_name, type_name(msg_type))
        return publisher

    # -- graph -------------------------------------------------------------------------
    def node_names(self) -> set[str]:
        return {name for name, _ns in self.node.get_node_names_and_namespaces()}

    # -- services and parameters ---------------------------------------------------------
    def call(self, srv_type: type, service: str, request: Any, sim_timeout: float = 5.0) -> Any:
        """Call a service; None when it is not available or does not answer in time."""
        client = self.node.create_client(srv_type, service)
        try:
            if not self.wait_for(client.service_is_ready, sim_timeout):
                return None
            future = client.call_async(request)
            if not self.wait_for(future.done, sim_timeout):
                return None
            return future.result()
        finally:
            self.node.destroy_client(client)

    def set_parameters(self, node: str, values: dict[str, Any],
                       sim_timeout: float = 5.0) -> list[SetParametersResult]:
        request = SetParameters.Request()
        request.parameters = [Parameter(k, value=v).to_parameter_msg() for k, v in values.items()]
        response = self.call(SetParameters, f"/{node}/set_parameters", request, sim_timeout)
        if response is None:
            raise StudentFailure(
                _("The node's set_parameters service did not answer within {seconds} s.").format(
                    seconds=sim_timeout),
                _("Is the node spinning? Parameter services are served by the executor."))
        return list(response.results)

    def get_parameters(self, node: str, names: Iterable[str],
                       sim_timeout: float = 5.0) -> dict[str, Any]:
        names = list(names)
        request = GetParameters.Request(names=names)
        response = self.call(GetParameters, f"/{node}/get_parameters", request, sim_timeout)
        if response is None:
            raise StudentFailure(
                _("The node's get_parameters service did not answer within {seconds} s.").format(
                    seconds=sim_timeout))
        if len(response.values) != len(names):
            raise GraderError(f"get_parameters returned {len(response.values)} values")
        return {n: parameter_value_to_python(v) for n, v in zip(names, response.values,
                                                                 strict=True)}
