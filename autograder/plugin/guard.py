"""The tampering guard: a test during which the student's program impersonated the world
or the grader on the graph is failed, not rewarded."""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING

import pytest

from autograder.core.errors import StudentFailure
from autograder.i18n import _
from autograder.plugin.probe import GRADER_NODES
from autograder.plugin.stash import settings_key

if TYPE_CHECKING:
    from autograder.plugin.probe import Probe

# Topics only the world publishes.
WORLD_TOPICS = ("/clock", "/odom", "/scan")


def tampering(probe: Probe) -> list[str]:
    """What on the graph impersonates the world or the grader, in plain words."""
    found = []
    for topic in WORLD_TOPICS:
        for info in probe.node.get_publishers_info_by_topic(topic):
            if info.node_name not in GRADER_NODES:
                found.append(_("node '{node}' publishes on {topic}, which the simulator "
                               "owns").format(node=info.node_name, topic=topic))
    names = [name for name, _ns in probe.node.get_node_names_and_namespaces()]
    for name in GRADER_NODES:
        if names.count(name) > 1:
            found.append(_("a second node is named '{name}', the grader's name").format(
                name=name))
    return found


@pytest.fixture(autouse=True)
def _graph_guard(request: pytest.FixtureRequest) -> Iterator[None]:
    """Fail any test during which the student tampered with the graph: not rewarded."""
    if "probe" not in request.fixturenames or settings_key not in request.config.stash:
        yield
        return
    probe = request.getfixturevalue("probe")
    before = tampering(probe)
    yield
    seen = before + [t for t in tampering(probe) if t not in before]
    if seen:
        raise StudentFailure(
            _("Tampering with the simulated world: {what}. Tests run while it happens are "
              "not graded.").format(what="; ".join(seen)),
            _("Publish only on the topics the exercise names; the world owns /clock, /odom "
              "and /scan."))
