"""click's own words in the active language.

click translates what it prints (``Error:``, ``Usage:``, "Missing argument", "No such
option") with the standard library's ``gettext``, which knows nothing of our catalogs, so
an Urdu run's usage errors would be English.  :func:`speak` points the ``_`` and
``ngettext`` of click's modules at ours; a string our catalog lacks stays click's English.
The strings below are click's own, marked here so that extraction puts them in
``messages.pot`` (those of a usage error; click's help pages keep the commands' English
docstrings, so their headings stay English too).
"""

from __future__ import annotations

import click.core
import click.exceptions
import click.formatting
import click.parser
import click.types

from autograder.i18n import N_, NN_, _, ngettext

_MODULES = (click.core, click.exceptions, click.formatting, click.parser, click.types)

WORDS = (
    N_("Error: {message}"), N_("Try '{command} {option}' for help."), N_("Usage:"),
    N_("Invalid value: {message}"), N_("Invalid value for {param_hint}: {message}"),
    N_("Missing argument"), N_("Missing option"), N_("Missing parameter"),
    N_("Missing {param_type}"), N_("Missing parameter: {param_name}"),
    N_("No such option {name!r}."), N_("No such command {name!r}."), N_("Missing command."),
    N_("Aborted!"), N_("Could not open file {filename!r}: {message}"),
    N_("Option {name!r} does not take a value."), N_("Argument {name!r} takes {nargs} values."),
    N_("{value!r} is not a valid {number_type}."), N_("{value} is not in the range {range}."),
    N_("file"), N_("directory"), N_("path"), N_("{name} {filename!r} does not exist."),
    N_("{name} {filename!r} is a file."), N_("{name} {filename!r} is a directory."),
    NN_("Did you mean {possibility}?", "(Did you mean one of: {possibilities}?)"),
    NN_("Got unexpected extra argument ({args})", "Got unexpected extra arguments ({args})"),
    NN_("Option {name!r} requires an argument.", "Option {name!r} requires {nargs} arguments."),
    NN_("{value!r} is not {choice}.", "{value!r} is not one of {choices}."),
)


def speak() -> None:
    """Make click translate with our catalogs, in whatever language is active when it
    speaks (idempotent; English is unchanged)."""
    for module in _MODULES:
        module._ = _  # type: ignore[attr-defined]
        if hasattr(module, "ngettext"):
            module.ngettext = ngettext  # type: ignore[attr-defined]
