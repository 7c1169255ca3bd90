"""benchmarks/footprint_roles.py sorts a grading's processes by what they are, from the
command lines a grading's processes show (issue 36's footprint breakdown)."""

from __future__ import annotations

import pytest

from benchmarks.footprint_roles import role

PY = "/opt/venv/bin/python"
TEMPLATE = f"{PY} -m autograder.grading.template 15 "
ZYGOTE = f"{PY} -s -m autograder.sandbox.contained.zygote 24 "


@pytest.mark.parametrize(("command", "parent", "expected"), [
    (TEMPLATE, f"{PY} /opt/venv/bin/autograder grade ex sub", "template"),
    (TEMPLATE, TEMPLATE, "child pytest"),  # forked from the template: its command line
    (f"{PY} -m pytest -p autograder.plugin tests/public", "anything", "child pytest"),
    (ZYGOTE, TEMPLATE, "zygote"),
    (ZYGOTE, ZYGOTE, "student"),  # forked from the zygote
    (f"{PY} -s /tmp/autograder-run/staged/node.py", f"{PY} -m pytest", "student"),
    (f"{PY} -I -m autograder.sandbox.startup_check strict", "x", "other"),
    ("/bin/sh -c sleep 1", "x", "other"),
])
def test_each_process_of_a_grading_has_its_role(command, parent, expected) -> None:
    assert role(command, parent) == expected
