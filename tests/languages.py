"""A fixture for test packages whose tests change the process's language."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from autograder.i18n import set_language


@pytest.fixture(autouse=True)
def english() -> Iterator[None]:
    """Each test starts in English and leaves English behind: ``--lang ur`` and a report
    in another language set the process's language."""
    set_language("en")
    yield
    set_language("en")
