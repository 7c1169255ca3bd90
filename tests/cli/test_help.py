"""Every command's --help reads as plain text: click prints docstrings as they are, so no
reStructuredText markup (``literal``, :role:`target`) may show."""

from __future__ import annotations

import re
from collections.abc import Iterator

import click
import pytest
from click.testing import CliRunner

from autograder.cli import main

RST = re.compile(r"``|:[a-z]+:`|`_\b|^\s*\.\. ", re.MULTILINE)


def _commands(command: click.Command, path: tuple[str, ...] = ()) -> Iterator[tuple[str, ...]]:
    """Every command's path, asked the way click asks (the lazy ``sim``, ``quiz`` and
    ``i18n`` groups are imported only then)."""
    yield path
    if isinstance(command, click.Group):
        ctx = click.Context(command)
        for name in command.list_commands(ctx):
            sub = command.get_command(ctx, name)
            assert sub is not None, name
            yield from _commands(sub, (*path, name))


@pytest.mark.parametrize("path", list(_commands(main)), ids=lambda p: " ".join(p) or "main")
def test_help_has_no_rst_markup(path: tuple[str, ...]) -> None:
    result = CliRunner().invoke(main, [*path, "--help"])
    assert result.exit_code == 0, result.output
    assert not RST.search(result.output), result.output
