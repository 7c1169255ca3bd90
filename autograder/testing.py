"""What an exercise's tests use, in one place: the types of the plugin's fixtures (for type
hints) and the failure a student can act on. The fixtures themselves come from the pytest
plugin, by name; docs/instructors/writing-exercises.md walks through each with an example.

``world`` (:class:`SimBridge`, module scope): the running simulated world::

    def test_survives_a_dropout(world: SimBridge, probe: Probe) -> None:
        start = world.now + 1.0                                # simulation seconds
        world.inject(Fault(kind="dropout", start=start, end=start + 3.0))
        probe.wait_sim(5.0)

``probe`` (:class:`Probe`, module scope): the grader's own node on the graph; ``subscribe``
gives an :class:`Inbox`: iterate it, or take its ``messages`` as a list::

    inbox: Inbox[String] = probe.subscribe(String, "/greeting")
    probe.publish(String, "name", String(data="Ada"))
    if not probe.wait_for(lambda: len(inbox) > 0, 2.0):      # 2 s of simulation time
        raise StudentFailure(_("Nothing came on `greeting`."), _("Publish from the callback."))
    first = inbox.messages[0].data                           # inbox.items: (stamp, message)

``student`` (:class:`StudentNode`, module scope): the student's node, started once per
module and already seen on the graph; ``start_node(params={...})`` starts another::

    def test_exits_on_a_bad_override(start_node) -> None:
        node: StudentNode = start_node({"max_linear_speed": 3.0}, wait_for_node=False)
        if node.wait_exit(10.0) in (None, 0):
            raise StudentFailure(_("The node kept running."), _("Exit non-zero."))

``credit`` (:class:`Credit`, function scope): partial credit for the running test::

    credit.award(0.5, _("Reached 2 of 4 goals."), _("Slow down near walls."))

``evidence`` (:class:`Evidence`): a chart for the report, ``evidence.intervals(title,
times, limit)``. Markers: ``@pytest.mark.points(n)``, ``@pytest.mark.visibility(v)``,
``pytestmark = pytest.mark.world(name)``, ``@pytest.mark.parameters({...})`` (the module's
``student`` overrides), ``@pytest.mark.reveal("status")``. The first line of a test's
docstring is its label; raise :class:`StudentFailure` for what the student can fix, and
anything else is reported as the grader's error, never as their zero.
"""

from __future__ import annotations

from autograder.core.errors import GraderError, StudentFailure
from autograder.plugin.credit import Credit, Evidence
from autograder.plugin.markers import MARKERS
from autograder.plugin.probe import Inbox, Probe
from autograder.plugin.student import StudentNode
from sim.bridge import SimBridge
from sim.faults import Fault

__all__ = ["MARKERS", "Credit", "Evidence", "Fault", "GraderError", "Inbox", "Probe",
           "SimBridge", "StudentFailure", "StudentNode"]
