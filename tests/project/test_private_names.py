"""No test reaches into a module's private names: a test goes through what the module offers
(its public functions and classes), so a module may rename or reshape its private helpers
without a test breaking for it. A helper with a contract of its own worth testing alone is
made public.

Counted, in every test file but the submissions' (which are students' code): an import of
a leading-underscore name from ``autograder``, ``sim`` or ``content``; such a name read off
a module of theirs (``module._name``, ``monkeypatch.setattr(module, "_name", ...)``); a call
of an object's private method (``run._limits()``) whose name a class of theirs defines as a
method and the test file does not define itself; and all of these in the text of code a
test runs in a subprocess. Not counted: ``_`` (gettext), dunders, a call on ``self`` or
``cls``, and an object's private attributes other than calls (``bridge._cond``), which this
check cannot tell from a local's.
"""

from __future__ import annotations

import ast
import re
from collections.abc import Iterator, Mapping
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


def private_methods() -> dict[str, tuple[str, ...]]:
    """Each private method name the classes of ours define, with those classes
    (``module.Class``)."""
    found: dict[str, list[str]] = {}
    for root in ROOTS:
        for path in sorted((REPO / root).rglob("*.py")):
            module = ".".join(path.relative_to(REPO).with_suffix("").parts)
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, ast.ClassDef):
                    for item in node.body:
                        if isinstance(item, ast.FunctionDef | ast.AsyncFunctionDef) \
                                and _private(item.name):
                            found.setdefault(item.name, []).append(f"{module}.{node.name}")
    return {name: tuple(owners) for name, owners in found.items()}


def _code_texts(tree: ast.AST) -> Iterator[tuple[int, str]]:
    """The strings of ``tree`` that may be code (they import something), with their line:
    an f-string whole, its replacement fields standing as ``_``."""
    texts, inside = [], set()
    for node in ast.walk(tree):
        if isinstance(node, ast.JoinedStr):
            parts = []
            for value in node.values:
                inside.add(id(value))
                parts.append(value.value if isinstance(value, ast.Constant) else "_")
            texts.append((node.lineno, "".join(str(part) for part in parts)))
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) \
                and id(node) not in inside:
            texts.append((node.lineno, node.value))
    return ((line, text) for line, text in texts if "import" in text)


def private_uses(source: str, methods: Mapping[str, tuple[str, ...]] | None = None
                 ) -> Iterator[tuple[int, str]]:
    """Each private name of our modules ``source`` uses, as ``module.name``, with its line;
    with ``methods`` (:func:`private_methods`), each call of one of those methods too, as
    ``module.Class.name``."""
    methods = methods or {}
    tree = ast.parse(source)
    modules: dict[str, str] = {}  # a local name -> the module of ours it stands for
    own = {node.name for node in ast.walk(tree)
           if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)}
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
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            name, base = node.func.attr, _dotted(node.func.value)
            if name in methods and name not in own and base not in ("self", "cls") \
                    and (base is None or base.split(".")[0] not in modules) \
                    and not (isinstance(node.func.value, ast.Call)
                             and _dotted(node.func.value.func) == "super"):
                yield node.lineno, " | ".join(f"{owner}.{name}" for owner in methods[name])
    for line, text in _code_texts(tree):
        try:
            found = list(private_uses(text, methods))
        except SyntaxError:  # a fragment of code, or prose: its imports by their words
            found = [(0, f"{match.group(1)}.{name}")
                     for match in re.finditer(
                         r"from ((?:autograder|sim|content)[\w.]*) import ([^\n]*)", text)
                     for name in re.split(r"[\s,()]+", match.group(2)) if _private(name)]
        yield from ((line, name) for _line, name in found)


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
    hand.run._limits()
    child = f"from autograder.sandbox import startup_check\\nstartup_check._stop({x!r})\\n"
'''
    methods = {"_limits": ("autograder.commands.hand_run.NodeRun",)}
    assert sorted(name for _line, name in private_uses(source, methods)) == [
        "autograder.commands.hand_run.NodeRun._limits",
        "autograder.core.results._hidden", "autograder.grading.footprint._read",
        "autograder.grading.run._record", "autograder.grading.run._seam",
        "autograder.sandbox.startup_check._stop", "sim.cli._warn"]


def test_an_objects_own_calls_and_a_tests_own_helpers_are_not_counted() -> None:
    source = '''
class Fake:
    def _helper(self):
        return self._limits() + super()._limits()

def _started(run):
    return run._started()
'''
    methods = {"_limits": ("a.B",), "_helper": ("a.B",), "_started": ("a.B",)}
    assert list(private_uses(source, methods)) == []


def test_the_methods_are_those_our_classes_define() -> None:
    methods = private_methods()
    assert "sim.physics.World" in methods["_build_robot"]
    assert all(_private(name) for name in methods)  # no dunder, no public name


METHODS = private_methods()


def test_no_test_uses_a_private_name_of_ours() -> None:
    found = {(path.relative_to(REPO).as_posix(), name): line
             for path in _test_files()
             for line, name in private_uses(path.read_text(encoding="utf-8"), METHODS)}
    new = sorted(f"{file}:{line}: {name}" for (file, name), line in found.items()
                 if (file, name) not in ALLOWED)
    assert not new, ("tests that use a private name: test through the public code, or make "
                     "the name public where it is a unit of its own:\n" + "\n".join(new))
    gone = sorted(f"{file}: {name}" for file, name in ALLOWED - set(found))
    assert not gone, "no longer used, remove from ALLOWED:\n" + "\n".join(gone)
