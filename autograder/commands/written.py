"""Where a command wrote the files it was asked for, said on stderr: a pipe on stdout
(``| head``) leaves it alone, so the student learns where the files are, in every
language."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import click

from autograder.i18n import _


def say_written(written: Iterable[tuple[str, Path]]) -> None:
    """One line per (option name, path) written: ``html``, ``log`` and any ``--NAME``."""
    from autograder.render.terminal import for_terminal

    for name, path in written:
        if name == "html":
            line = _("Wrote {path} (--html): open it in a browser.").format(path=path)
        elif name == "log":
            line = _("Wrote {path}: the programs' whole output.").format(path=path)
        else:
            line = _("Wrote {path} (--{option}).").format(path=path, option=name)
        click.echo(for_terminal(line), err=True)
