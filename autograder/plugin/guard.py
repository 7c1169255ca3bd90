"""The tampering guard: a test during which the student's program impersonated the world
or the grader on the graph is failed, not rewarded; one during which another user's
program joined the grading's ROS domain is the grader's failure ("disturbed"), never
blamed on the student.

A :class:`GraphWatch` looks at the probe's graph every ``WATCH_EVERY`` wall seconds, from
a thread of its own, for as long as the module's probe lives, and keeps when it saw each
finding.  A test is charged with all that was seen since the previous test ended (the
first test: since the probe started), so a foreign publisher that lives a fraction of a
second inside a test fails that test, and one seen between two tests fails the next.

Where runs share the machine's network (isolation by user, basic isolation) it also looks
at the wire (:class:`Wire`): the UDP sockets bound to Fast DDS's ports, each with the user
who made it. A socket on this grading's domain made by a user that is neither the
grader's nor the student's is a stranger's; one the student's own user made on another
domain's ports is the student joining another grading.
"""

from __future__ import annotations

import dataclasses
import threading
import time
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING, Any

import pytest

from autograder.core.errors import Disturbed, StudentFailure
from autograder.i18n import _
from autograder.plugin.probe import GRADER_NODES
from autograder.plugin.stash import settings_key

if TYPE_CHECKING:
    from autograder.plugin.probe import Probe

# Topics only the world publishes.
WORLD_TOPICS = ("/clock", "/odom", "/scan")
# Wall seconds between two looks: a publisher that lives 0.3 s is seen about ten times.
WATCH_EVERY = 0.025

# A finding: ("publishes", node, topic), ("named", name, ""), ("wanders", domain, "")
# (the student's), or ("stranger", user, domain) (a disturbance, not the student's).
Finding = tuple[str, str, str]


@dataclasses.dataclass(frozen=True)
class Wire:
    """Who may have sockets on this test module's ROS domain: the grader's users and the
    student's (``students``: the users of the grading's other modules too, the same
    student's program); ``read`` lists the machine's (domain, user) sockets."""

    domain: int
    grader: frozenset[int]
    student: int
    read: Callable[[], list[tuple[int, int]]]
    students: frozenset[int] = frozenset()

    def look(self) -> list[Finding]:
        found = set()
        ours = self.grader | self.students | {self.student}
        for domain, uid in self.read():
            if domain == self.domain and uid not in ours:
                found.add(("stranger", str(uid), str(domain)))
            elif domain != self.domain and uid == self.student and uid not in self.grader:
                found.add(("wanders", str(domain), ""))
        return sorted(found)


def _publishing(node: Any) -> list[Finding]:
    """Nodes other than the grader's that publish on the world's topics."""
    return [("publishes", info.node_name, topic) for topic in WORLD_TOPICS
            for info in node.get_publishers_info_by_topic(topic)
            if info.node_name not in GRADER_NODES]


def _named_twice(node: Any) -> list[Finding]:
    """The grader's names that a second node carries."""
    names = [name for name, _ns in node.get_node_names_and_namespaces()]
    return [("named", name, "") for name in GRADER_NODES if names.count(name) > 1]


def _describe(finding: Finding) -> str:
    kind, node, topic = finding
    if kind == "stranger":
        return _("a program of another user (uid {uid}) joined this grading's ROS domain "
                 "{domain}").format(uid=node, domain=topic)
    if kind == "wanders":
        return _("your program joined ROS domain {domain}, which is not its own").format(
            domain=node)
    if kind == "publishes":
        return _("node '{node}' publishes on {topic}, which the simulator owns").format(
            node=node, topic=topic)
    return _("a second node is named '{name}', the grader's name").format(name=node)


def tampering(probe: Probe) -> list[str]:
    """What on the graph impersonates the world or the grader, in plain words."""
    return [_describe(f) for f in _publishing(probe.node) + _named_twice(probe.node)]


class GraphWatch:
    """Looks at ``probe``'s graph every ``every`` wall seconds (:meth:`start` to
    :meth:`stop`) and keeps, for each finding, the spans of time it was seen in."""

    def __init__(self, probe: Probe, every: float = WATCH_EVERY,
                 clock: Callable[[], float] = time.monotonic,
                 wire: Wire | None = None) -> None:
        self._probe = probe
        self._wire = wire
        self._every = every
        self._clock = clock
        self._lock = threading.Lock()
        self._looking = threading.Lock()  # one look at a time: the thread's or a charge's
        # finding -> [first, last] seen, one span per run of consecutive looks
        self._spans: dict[Finding, list[list[float]]] = {}
        self._last: set[Finding] = set()
        # Publisher counts on WORLD_TOPICS when a look found them all the grader's.
        self._clean: list[int] | None = None
        self._charged = clock()  # what was seen before this was charged to a test
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self) -> None:
        """Look now and then every ``every`` seconds, from a daemon thread."""
        self._thread = threading.Thread(target=self._run, daemon=True, name="graph-watch")
        self._thread.start()

    def stop(self) -> None:
        """No more looks (call before the probe's node goes); what was seen stays."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None

    def _run(self) -> None:
        due = self._clock()
        while not self._stop.is_set():
            try:
                self.look()
            except Exception:
                if self._stop.is_set():  # the node went while we looked
                    return
                raise
            due = max(due + self._every, self._clock())  # a slow look skips, never bunches
            self._stop.wait(due - self._clock())

    def look(self) -> None:
        """Look at the graph once and note the time of what is there."""
        with self._looking:
            found = set(self._publishing() + _named_twice(self._probe.node))
            if self._wire is not None:
                found.update(self._wire.look())
            with self._lock:  # stamped under the lock: a look is before or after a charge
                now = self._clock()
                for finding in found:
                    spans = self._spans.setdefault(finding, [])
                    if finding in self._last and spans:
                        spans[-1][1] = now
                    else:
                        spans.append([now, now])
                self._last = found

    def _publishing(self) -> list[Finding]:
        """:func:`_publishing`, read only when the publisher counts changed since a look
        that found all of them the grader's: the grader's own stay while its probe lives,
        so the same counts are the same publishers (counting costs a fifth of reading)."""
        node = self._probe.node
        counts = [node.count_publishers(topic) for topic in WORLD_TOPICS]
        if counts == self._clean:
            return []
        found = _publishing(node)
        self._clean = None if found else counts
        return found

    @property
    def seen(self) -> dict[Finding, list[tuple[float, float]]]:
        """Every finding with the (first, last) times of each span it was seen in."""
        with self._lock:
            return {f: [(a, b) for a, b in spans] for f, spans in self._spans.items()}

    def charge(self) -> list[str]:
        """After a look, what of the student's was seen since the last charge (or the
        start), in words, in the order first seen; later charges start from now."""
        return self.charge_split()[0]

    def charge_split(self) -> tuple[list[str], list[tuple[str, int]]]:
        """:meth:`charge`, and besides what strangers did meanwhile (disturbances: in
        words, with the stranger's user)."""
        self.look()
        with self._lock:
            since, self._charged = self._charged, self._clock()
            due = [(min(a for a, b in spans if b >= since), f)
                   for f, spans in self._spans.items() if any(b >= since for _a, b in spans)]
        due.sort()
        return ([_describe(f) for _first, f in due if f[0] != "stranger"],
                [(_describe(f), int(f[1])) for _first, f in due if f[0] == "stranger"])


# On a test module: the watch started with its probe (plugin/world.py).
graph_watch_key = pytest.StashKey[GraphWatch]()


def _module_watch(item: pytest.Item) -> GraphWatch | None:
    for node in reversed(item.listchain()):
        watch = node.stash.get(graph_watch_key, None)
        if watch is not None:
            return watch
    return None


@pytest.fixture(autouse=True)
def _graph_guard(request: pytest.FixtureRequest) -> Iterator[None]:
    """Fail any test during which the student tampered with the graph: not rewarded."""
    if "probe" not in request.fixturenames or settings_key not in request.config.stash:
        yield
        return
    probe = request.getfixturevalue("probe")
    watch = _module_watch(request.node)
    own = watch is None
    if watch is None:  # a probe the module made itself: watch it for this test
        watch = GraphWatch(probe)
        watch.start()
    try:
        yield
        seen, strangers = watch.charge_split()
    finally:
        if own:
            watch.stop()
    if strangers:  # whatever the student did meanwhile: this test proves nothing
        raise Disturbed(_(
            "Disturbed: {what}. This grading cannot be trusted; grade again.").format(
            what="; ".join(words for words, _uid in strangers)),
            tuple(sorted({uid for _words, uid in strangers})))
    if seen:
        raise StudentFailure(
            _("Tampering with the simulated world: {what}. Tests run while it happens are "
              "not graded.").format(what="; ".join(seen)),
            _("Publish only on the topics the exercise names; the world owns /clock, /odom "
              "and /scan."))
