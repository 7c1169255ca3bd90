"""Tests mirror the packages: each module of ``autograder``, ``sim`` and ``content`` has a test
file of its own at the same place under tests/ (``autograder/quiz/types/numeric.py`` ->
``tests/quiz/types/test_numeric.py``, ``sim/svg.py`` -> ``tests/sim/test_svg.py``,
``content/document.py`` -> ``tests/content/test_document.py``), so a maintainer finds a
module's tests where its name says.

:data:`WITHOUT_OWN_TESTS` lists the modules that have none yet; it is empty now, and stays
so: a new module comes with its test file.
"""

from __future__ import annotations

from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
ROOTS = ("autograder", "sim", "content")
SKIPPED = ("__init__.py", "__main__.py")

WITHOUT_OWN_TESTS: frozenset[str] = frozenset()


def own_test_file(module: Path) -> Path:
    """Where the tests of ``module`` (relative to the repository) live."""
    parts = module.parts[1:] if module.parts[0] == "autograder" else module.parts
    return Path("tests", *parts[:-1], f"test_{module.stem}.py")


def modules_without_own_tests() -> set[str]:
    missing = set()
    for root in ROOTS:
        for path in (REPO / root).rglob("*.py"):
            module = path.relative_to(REPO)
            if path.name not in SKIPPED and not (REPO / own_test_file(module)).is_file():
                missing.add(module.as_posix())
    return missing


def test_where_a_modules_tests_live() -> None:
    assert own_test_file(Path("autograder/quiz/types/numeric.py")) == \
        Path("tests/quiz/types/test_numeric.py")
    assert own_test_file(Path("sim/svg.py")) == Path("tests/sim/test_svg.py")
    assert own_test_file(Path("content/document.py")) == Path("tests/content/test_document.py")


def test_every_new_module_has_its_own_test_file() -> None:
    missing = modules_without_own_tests()
    new = sorted(missing - WITHOUT_OWN_TESTS)
    assert not new, ("modules without a test file of their own (write it where "
                     "own_test_file says):\n" + "\n".join(new))
    done = sorted(WITHOUT_OWN_TESTS - missing)
    assert not done, ("these have their test file now (or are gone): remove them from "
                      "WITHOUT_OWN_TESTS:\n" + "\n".join(done))
