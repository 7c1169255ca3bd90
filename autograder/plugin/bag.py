"""Recording a test module's graph as a rosbag2 bag (``grade --record DIR``): the world's
topics, what the probe saw of the student's node, and the transforms (:mod:`sim.bag`).

The bag is written by the grader's pytest child (world and probe), never by the student's
sandbox.  A recording that cannot be made or finished is a warning in the report, never a
test's failure: nothing here raises into a test.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from autograder.i18n import _
from autograder.plugin.stash import reporter_key, settings_key

if TYPE_CHECKING:
    from autograder.plugin.probe import Probe
    from sim.bag import BagRecorder
    from sim.bridge import SimBridge

# The recorder of each module (by its node id), for the probe fixture to find.
bags_key = pytest.StashKey[dict[str, "BagRecorder"]]()


def _folder(request: pytest.FixtureRequest, root: Path) -> Path:
    """``root/<module name>``, made unique within the run (public and hidden tests may
    hold modules of the same name)."""
    base = re.sub(r"[^\w.-]+", "_", Path(str(request.node.path)).stem)
    taken = {bag.directory for bag in request.config.stash.get(bags_key, {}).values()}
    names = [base, *(f"{base}_{n}" for n in range(2, 100))]
    return next(root / n for n in names if root / n not in taken)


def _warn(request: pytest.FixtureRequest, messages: list[str]) -> None:
    reporter = request.config.stash.get(reporter_key, None)
    if reporter is not None and messages:
        reporter.data.setdefault("warnings", []).extend(messages)


def open_bag(request: pytest.FixtureRequest, bridge: SimBridge,
             world: str) -> BagRecorder | None:
    """Start recording ``bridge`` when the run records; None otherwise, or if the bag
    cannot be made (a warning says why)."""
    settings = request.config.stash.get(settings_key, None)
    if settings is None or not settings.record:
        return None
    from sim.bag import BagRecorder

    folder = _folder(request, Path(settings.record))
    try:
        recorder = BagRecorder(folder, mount=getattr(bridge.sim.lidar, "mount", (0.0, 0.0, 0.0)),
                               custom_data={"exercise": Path(settings.exercise).name,
                                            "test_module": request.node.nodeid, "world": world})
    except Exception as exc:  # no recording is no reason to fail a test
        _warn(request, [_("The run could not be recorded in {path}: {error}").format(
            path=folder, error=exc)])
        return None
    bridge.add_tap(recorder)
    request.config.stash.setdefault(bags_key, {})[request.node.nodeid] = recorder
    return recorder


def attach_probe(request: pytest.FixtureRequest, probe: Probe) -> None:
    """Record what ``probe`` sees of the student's node into its module's bag, if any."""
    recorder = request.config.stash.get(bags_key, {}).get(request.node.nodeid)
    if recorder is not None:
        probe.add_tap(recorder)


def close_bag(request: pytest.FixtureRequest, recorder: BagRecorder | None) -> None:
    """Finish the bag (after the world and probe stopped) and name it in the report."""
    if recorder is None:
        return
    folder = recorder.close()
    reporter = request.config.stash.get(reporter_key, None)
    if folder is not None and reporter is not None:
        reporter.data.setdefault("bags", {})[folder.name] = str(folder)
    _warn(request, recorder.warnings())
