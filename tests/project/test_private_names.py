"""No test reaches into a module's private names: a test goes through what the module offers
(its public functions and classes), so a module may rename or reshape its private helpers
without a test breaking for it. A helper with a contract of its own worth testing alone is
made public.

Counted, in every test file but the submissions' (which are students' code): an import of
a leading-underscore name from ``autograder``, ``sim`` or ``content``; such a name read off
a module of theirs (``module._name``, ``monkeypatch.setattr(module, "_name", ...)``); and
such an import in the text of code a test runs in a subprocess. Not counted: ``_`` (gettext),
dunders, and an object's own attributes (``bridge._cond``), which this check cannot
tell from a local's.
"""

from __future__ import annotations

import ast
import re
from collections.abc import Iterator
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
TESTS = REPO / "tests"
ROOTS = ("autograder", "sim", "content")

# (test file, module.name) pairs still allowed: none. Never add one; make the name public
# where it is a unit with a contract, or test it through the function that uses it.
ALLOWED: frozenset[tuple[str, str]] = frozenset()


def _ours(module: str | None) -> bool:
    return bool(module) and module.split(".")[0] in ROOTS  # type: ignore[union-attr]


def _private(name: str) -> bool:
    return name.startswith("_") and name != "_" and not (
        name.startswith("__") and name.endswith("__"))


def _test_files() -> Iterator[Path]:
    for path in sorted(TESTS.rglob("*.py")):
        # This file's own example of what is counted is not a use.
        if "submissions" not in path.relative_to(TESTS).parts and path != Path(__file__):
            yield path


def _dotted(node: ast.expr) -> str | None:
    """``a.b.c`` of an attribute chain of plain names, else None."""
    parts = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if not isinstance(node, ast.Name):
        return None
    return ".".join([node.id, *reversed(parts)])


def private_uses(source: str) -> Iterator[tuple[int, str]]:
    """Each private name of our modules ``source`` uses, as ``module.name``, with its line."""
    tree = ast.parse(source)
    modules: dict[str, str] = {}  # a local name -> the module of ours it stands for
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and _ours(node.module):
            for alias in node.names:
                if _private(alias.name):
                    yield node.lineno, f"{node.module}.{alias.name}"
                modules[alias.asname or alias.name] = f"{node.module}.{alias.name}"
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if _ours(alias.name):
                    local = alias.asname or alias.name.split(".")[0]
                    modules[local] = alias.name if alias.asname else local
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and _private(node.attr):
            base = _dotted(node.value)
            if base is not None and base.split(".")[0] in modules:
                head, _dot, rest = base.partition(".")
                yield node.lineno, ".".join(filter(None, (modules[head], rest, node.attr)))
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) \
                and node.func.attr in ("setattr", "delattr") and len(node.args) >= 2:
            target, name = node.args[0], node.args[1]
            base = _dotted(target)
            if isinstance(name, ast.Constant) and isinstance(name.value, str) \
                    and _private(name.value) and base is not None \
                    and base.split(".")[0] in modules:
                head, _dot, rest = base.partition(".")
                yield node.lineno, ".".join(filter(None, (modules[head], rest, name.value)))
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            for found in re.finditer(r"from ((?:autograder|sim|content)[\w.]*) import ([^\n]*)",
                                     node.value):
                for name in re.split(r"[\s,()]+", found.group(2)):
                    if _private(name):
                        yield node.lineno, f"{found.group(1)}.{name}"


def test_the_check_sees_each_way_in() -> None:
    source = '''
import sim.cli
from autograder.grading import run as running
from autograder.core.results import _hidden, exact
from autograder.i18n import _

def test(monkeypatch):
    sim.cli._warn(1)
    running._record
    monkeypatch.setattr(running, "_seam", None)
    code = "from autograder.grading.footprint import _read, process_kb"
    exact(_("fine"))
'''
    assert sorted(name for _line, name in private_uses(source)) == [
        "autograder.core.results._hidden", "autograder.grading.footprint._read",
        "autograder.grading.run._record", "autograder.grading.run._seam", "sim.cli._warn"]


def test_no_test_uses_a_private_name_of_ours() -> None:
    found = {(path.relative_to(REPO).as_posix(), name): line
             for path in _test_files()
             for line, name in private_uses(path.read_text(encoding="utf-8"))}
    new = sorted(f"{file}:{line}: {name}" for (file, name), line in found.items()
                 if (file, name) not in ALLOWED)
    assert not new, ("tests that use a private name: test through the public code, or make "
                     "the name public where it is a unit of its own:\n" + "\n".join(new))
    gone = sorted(f"{file}: {name}" for file, name in ALLOWED - set(found))
    assert not gone, "no longer used, remove from ALLOWED:\n" + "\n".join(gone)
