"""The autoescaped Jinja2 environment of every page (quiz pages and grading reports): the
package's ``templates/``, with ``_``, ``ngettext`` and the bidi filters of
:mod:`autograder.i18n.text`."""

from __future__ import annotations

import jinja2
from markupsafe import Markup

from autograder.i18n import _, ngettext
from autograder.i18n.text import plain, rich, sentence, with_output

FONT_STACK_UR = ('"Noto Nastaliq Urdu", "Jameel Noori Nastaleeq", "Urdu Typesetting", '
                 '"Noto Naskh Arabic", serif')
# Latin runs inside Urdu (``:lang(en)``): Nastaliq fonts have digits but no Latin letters,
# so left to the Urdu stack a run would mix a fallback serif with Nastaliq digits.
FONT_STACK_LATIN = '"Noto Sans", "DejaVu Sans", system-ui, sans-serif'


def _environment() -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.PackageLoader("autograder", "templates"),
        autoescape=jinja2.select_autoescape(["html"], default=True),
        trim_blocks=True, lstrip_blocks=True, undefined=jinja2.StrictUndefined)
    env.globals.update(_=_, ngettext=ngettext, font_stack_ur=Markup(FONT_STACK_UR),
                       font_stack_latin=Markup(FONT_STACK_LATIN))
    env.filters.update(rich=rich, plain=plain, bidi=sentence, with_output=with_output)
    return env


_ENV = _environment()


def environment() -> jinja2.Environment:
    """The autoescaped template environment shared by quiz pages and grading reports."""
    return _ENV
