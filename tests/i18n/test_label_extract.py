"""The extractor of exercise test files: Babel's own ``_()`` messages, and each test's label
(the first line of its docstring, at the docstring's line, marked "test label" for
translators); a file that does not parse still gives its calls."""

from __future__ import annotations

import io

from babel.messages.extract import DEFAULT_KEYWORDS, extract

from autograder.i18n.label_extract import extract_tests

SOURCE = b'''\
from autograder.i18n import _


def helper():
    """Not a test: no label."""
    return _("the robot never moved")


def test_drives_to_the_goal():
    """Drives to the goal
    within 30 s, without touching a wall."""
    assert helper()


async def test_async_label():

    """  Answers in time  """


def test_without_docstring():
    pass


def test_blank_docstring():
    """   """


class TestGroup:
    def test_in_a_class(self):
        """Counts every beam"""
'''


def _extract(source: bytes) -> list[tuple]:
    return list(extract_tests(io.BytesIO(source), DEFAULT_KEYWORDS, ["NOTE:"], {}))


def test_calls_then_each_tests_label_at_its_docstring():
    found = _extract(SOURCE)
    assert found[0][:3] == (6, "_", "the robot never moved")
    labels = {message: (line, comments) for line, func, message, comments in found[1:]
              if func == "_"}
    assert labels == {"Drives to the goal": (10, ["test label"]),
                      "Answers in time": (17, ["test label"]),
                      "Counts every beam": (30, ["test label"])}
    assert len(found) == 4  # no label for a helper, a missing or a blank docstring


def test_a_file_that_does_not_parse_gives_its_calls_only():
    found = _extract(b'x = _("still found")\ndef test_broken() -> :\n    """Lost"""\n')
    assert [message for _line, _func, message, _c in found] == ["still found"]


def test_a_file_with_an_unclosed_bracket_gives_the_calls_before_it():
    found = _extract(b'x = _("still found")\ny = f(\ndef test_broken():\n    """Lost"""\n')
    assert [message for _line, _func, message, _c in found] == ["still found"]


def test_babel_runs_it_by_module_path_with_the_label_comment():
    messages = list(extract("autograder.i18n.label_extract:extract_tests",
                            io.BytesIO(SOURCE)))
    assert (10, "Drives to the goal", ["test label"], None) in messages
