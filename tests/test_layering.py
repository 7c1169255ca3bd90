"""Imports run one way between the packages: each package imports only those in lower tiers,
never a sibling of its own tier nor anything above it, so the package graph has no cycle.

The tiers, lowest first, are the contract; a new package goes in a tier here before it is
imported anywhere. Every import counts, those inside functions too: a lazy import is still
an arrow, only a cheaper one.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
ROOTS = ("content", "sim", "autograder")

TIERS: tuple[frozenset[str], ...] = tuple(frozenset(tier) for tier in (
    {"content"},                       # the course's files and the low layers' gettext
    {"sim"},                           # the world: usable without the grader
    {"autograder"},                    # the package itself: its version
    {"autograder.i18n"},               # the active language, bidi text, the templates
    {"autograder.core"},               # results, report, settings, exercise files
    {"autograder.sandbox"},            # containing a student's program
    {"autograder.plugin", "autograder.grading", "autograder.render", "autograder.quiz"},
    {"autograder.commands"},           # what each command does, as plain functions
    {"autograder.cli", "autograder.testing"},  # the click layer; what exercise tests import
    {"autograder.__main__"},
))

ALLOWED_BACK_ARROWS: frozenset[tuple[str, str]] = frozenset()
"""(importer, imported) pairs that break the tiers. Keep it empty: move the code instead."""


def _modules() -> Iterator[tuple[str, Path]]:
    for root in ROOTS:
        for path in sorted((REPO / root).rglob("*.py")):
            parts = list(path.relative_to(REPO).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            yield ".".join(parts), path


def _imported(module: str, path: Path) -> Iterator[tuple[str, int]]:
    """Every module ``module`` imports (absolute names), with the line of the import."""
    package = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            yield from ((alias.name, node.lineno) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[:len(package) - node.level + 1]
                name = ".".join([*base, *([node.module] if node.module else [])])
            else:
                name = node.module or ""
            yield name, node.lineno
            yield from ((f"{name}.{alias.name}", node.lineno) for alias in node.names)


def package_of(module: str) -> str | None:
    """The package a module belongs to in :data:`TIERS` (None: not ours)."""
    parts = module.split(".")
    if parts[0] not in ROOTS:
        return None
    if parts[0] != "autograder" or len(parts) == 1:
        return parts[0]
    return f"autograder.{parts[1]}"


def _tier(package: str) -> int:
    for index, tier in enumerate(TIERS):
        if package in tier:
            return index
    raise AssertionError(f"{package} is in no tier of tests/test_layering.py: place it")


def _arrows() -> dict[tuple[str, str], list[str]]:
    found: dict[tuple[str, str], list[str]] = {}
    ours = dict(_modules())
    for module, path in ours.items():
        importer = package_of(module)
        assert importer is not None
        for name, line in _imported(module, path):
            target = package_of(name)
            if target is not None and target != importer and name in ours:
                where = f"{path.relative_to(REPO)}:{line} imports {name}"
                found.setdefault((importer, target), []).append(where)
    return found


def back_arrows(arrows: dict[tuple[str, str], list[str]]) -> list[str]:
    """The arrows that go sideways or up the tiers, one line each, with where."""
    return [f"{importer} -> {target}: {sites[0]}"
            for (importer, target), sites in sorted(arrows.items())
            if (importer, target) not in ALLOWED_BACK_ARROWS
            and _tier(target) >= _tier(importer)]


def cycles(arrows: dict[tuple[str, str], list[str]]) -> list[str]:
    """The packages from which the import graph leads back to themselves."""
    graph: dict[str, set[str]] = {}
    for importer, target in arrows:
        graph.setdefault(importer, set()).add(target)

    def reaches(start: str, goal: str, seen: set[str]) -> bool:
        for step in graph.get(start, ()):
            if step == goal or (step not in seen and reaches(step, goal, seen | {step})):
                return True
        return False

    return sorted(p for p in graph if reaches(p, p, {p}))


ARROWS = _arrows()


def test_every_package_has_a_tier() -> None:
    packages = {package_of(module) for module, _ in _modules()}
    for package in packages:
        assert package is not None
        _tier(package)


def test_imports_run_downwards_only() -> None:
    wrong = back_arrows(ARROWS)
    assert not wrong, "imports against the tiers:\n" + "\n".join(wrong)


def test_no_cycle_between_packages() -> None:
    assert not cycles(ARROWS)


@pytest.mark.parametrize(("importer", "target"), [
    ("content", "sim"), ("sim", "autograder.i18n"), ("autograder.i18n", "autograder.core"),
    ("autograder.render", "autograder.quiz"), ("autograder.quiz", "autograder.cli"),
    ("autograder.sandbox", "autograder.grading")])
def test_a_new_back_arrow_is_named_with_its_line(importer: str, target: str) -> None:
    """The checks themselves: an arrow against the tiers, added to the real graph, is
    reported with the file and line that made it, and so is the cycle it closes."""
    site = f"{importer.replace('.', '/')}/x.py:1 imports {target}"
    arrows = {**ARROWS, (target, importer): ["forward"], (importer, target): [site]}
    assert any(line.endswith(site) for line in back_arrows(arrows))
    assert importer in cycles(arrows)


def test_a_forward_arrow_passes() -> None:
    arrows = {**ARROWS, ("autograder.commands", "content"): ["commands/x.py:1 imports content"]}
    assert back_arrows(arrows) == [] and cycles(arrows) == []
