"""The markers an exercise's tests carry, and what is wrong with a test's, for its author."""

from __future__ import annotations

from fractions import Fraction

import pytest

MARKERS = {
    "points": "points(n): points the test is worth, a positive number (default 1)",
    "visibility": "visibility(v): 'visible', 'hidden' or 'after_published' (default: hidden "
                  "for tests under a hidden/ folder)",
    "world": "world(name): the world this module's tests run in (in the module's pytestmark)",
    "parameters": "parameters(dict): -p overrides the module's `student` node starts with "
                  "(in the module's pytestmark)",
    "reveal": "reveal(what): what a student sees of a failure: 'message' or 'status' "
              "(default: 'message' for visible tests, 'status' for hidden ones)",
}

# Markers the module's world and student node are started with, once for every test in it.
MODULE_ONLY = ("world", "parameters")


def marker_problem(item: pytest.Item) -> str | None:
    """What is wrong with a test's markers, for its author; None if nothing."""
    checks = {
        "points": lambda v: isinstance(v, (int, Fraction)) and not isinstance(v, bool)
        and v > 0 or isinstance(v, float) and v > 0,
        "visibility": lambda v: v in ("visible", "hidden", "after_published"),
        "reveal": lambda v: v in ("message", "status"),
        "world": lambda v: isinstance(v, str) and bool(v),
        "parameters": lambda v: isinstance(v, dict),
    }
    for name, valid in checks.items():
        marker = item.get_closest_marker(name)
        if marker is not None and (len(marker.args) != 1 or not valid(marker.args[0])):
            return f"{item.nodeid}: marker {MARKERS[name]}; got {marker.args!r}"
    for name in MODULE_ONLY:  # read by module-scoped fixtures: on a test or class, unused
        for node in item.listchain():
            if not isinstance(node, pytest.Module) and any(
                    m.name == name for m in getattr(node, "own_markers", ())):
                return (f"{item.nodeid}: marker {MARKERS[name]}; found on "
                        f"{node.name!r}, where it would not be used")
    return None
