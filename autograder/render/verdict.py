"""What every output format says about core tests (exercise.yaml's ``core``): a core
test's label marked as such, and which core tests kept a grading from passing.

One wording for all formats, in the active language, so the terminal, the HTML page,
Gradescope and JUnit name the same tests in the same words.
"""

from __future__ import annotations

from autograder.core.results import RunResult, TestResult
from autograder.i18n import _, ngettext


def core_label(test: TestResult) -> str:
    """The test's label, marked "(core)" if it is a core test."""
    if not test.core:
        return test.label
    return _("{label} (core)").format(label=test.label)


def core_heading(result: RunResult) -> str | None:
    """The sentence before the list of core tests that did not pass, or None if every core
    test passed. A whole grading is "not passed" for them; a partial run (``check``) says
    the grade cannot pass while they fail. Nothing when the grader failed: that says so."""
    missed = len(result.core_missed)
    if not missed or result.grader_error:
        return None
    if result.complete:
        return ngettext(
            "Not passed: this core test failed, and every core test must pass, whatever "
            "the points:",
            "Not passed: these {count} core tests failed, and every core test must pass, "
            "whatever the points:", missed).format(count=missed)
    return ngettext(
        "This core test failed; the grade cannot pass until it passes:",
        "These {count} core tests failed; the grade cannot pass until they pass:",
        missed).format(count=missed)


def core_lines(result: RunResult) -> list[str]:
    """The heading, then each core test that did not pass by its label; empty if none."""
    heading = core_heading(result)
    if heading is None:
        return []
    return [heading, *(f"- {test.label}" for test in result.core_missed)]


def core_note() -> str:
    """What a failed core test's own entry says (JUnit's failure text)."""
    return _("A core test: the grading does not pass without it, whatever the points.")
