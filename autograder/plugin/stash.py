"""Where the plugin keeps its state on pytest's config and items (``config.stash``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from autograder.core.errors import StudentFailure
from autograder.core.settings import RunSettings

if TYPE_CHECKING:
    pass

settings_key = pytest.StashKey[RunSettings]()
reporter_key = pytest.StashKey["GradingReporter"]()
credit_key = pytest.StashKey["Credit"]()
evidence_key = pytest.StashKey["Evidence"]()
# On a test module: the probe's watch on message types (plugin/msgtypes.py).
type_watch_key = pytest.StashKey["TypeWatch"]()
# The world of the test module running now, None between modules (the reporter reads its
# simulation time around each test).
world_key = pytest.StashKey["SimBridge | None"]()
# The student's node failed to appear once: later starts in the run fail at once.
startup_key = pytest.StashKey[StudentFailure]()
