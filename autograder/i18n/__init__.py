"""The one place that binds ``_`` and ``ngettext`` to the active language.

Nothing is installed into builtins.  Catalogs live in ``locales/<lang>/LC_MESSAGES/``
of the course tree as ``.po`` sources; a compiled ``.mo`` beside a source is used when it is
up to date, otherwise the source is compiled in memory with Babel, so a fresh clone needs
no build step and a stale ``.mo`` never hides a translation.  The platform's own catalogs
also ship inside the package (``autograder/locales``): a course tree without ``locales/``
(what the CI recipes point ``AUTOGRADER_COURSE`` at) still speaks the language.
"""

from __future__ import annotations

import gettext as _gettext
import importlib.resources
import os
from functools import cache
from pathlib import Path

import content.i18n
from content.course import course_root

DOMAIN = "messages"
LANGUAGES = ("en", "ur")
RTL_LANGUAGES = frozenset({"ur", "ar", "fa", "he"})

_active = "en"


def locales_dir() -> Path:
    """The course's ``locales/`` folder (``AUTOGRADER_LOCALES`` overrides it)."""
    env = os.environ.get("AUTOGRADER_LOCALES")
    if env:
        return Path(env)
    return course_root() / "locales"


def packaged_locales() -> Path:
    """The catalogs shipped inside the package (the checkout's ``locales/``)."""
    return Path(str(importlib.resources.files("autograder") / "locales"))


def catalog_folder(lang: str, domain: str = DOMAIN) -> Path:
    """Where ``lang``'s ``domain`` catalog is read from: the course's ``locales/`` when it
    holds that catalog, else the package's."""
    course = locales_dir() / lang / "LC_MESSAGES"
    if (course / f"{domain}.po").exists() or (course / f"{domain}.mo").exists():
        return course
    return packaged_locales() / lang / "LC_MESSAGES"


@cache
def translations(lang: str, domain: str = DOMAIN) -> _gettext.NullTranslations:
    """Translations for ``lang`` in ``domain``; English (the source) is a null catalog."""
    if lang == "en":
        return _gettext.NullTranslations()
    return content.i18n.load_catalog(catalog_folder(lang, domain), lang, domain)


def set_language(lang: str) -> None:
    """Make ``lang`` the language of every later ``_`` call in this process, the
    simulator's and the content files' messages included (:mod:`content.i18n` binds their
    ``_``: they import nothing of ``autograder``)."""
    global _active
    _active = lang
    content.i18n.set_language(
        lang, lambda: catalog_folder(content.i18n.get_language()).parent.parent)


def get_language() -> str:
    return _active


def is_rtl(lang: str | None = None) -> bool:
    return (lang or _active).split("_")[0] in RTL_LANGUAGES


def _(message: str) -> str:
    """Translate ``message``; use named placeholders: ``_("{path} not found").format(path=p)``."""
    return translations(_active).gettext(message)


def ngettext(singular: str, plural: str, n: int) -> str:
    return translations(_active).ngettext(singular, plural, n)


def pgettext(context: str, message: str) -> str:
    return translations(_active).pgettext(context, message)


def content_text(context: str, message: str) -> str:
    """Course content (quiz and exercise text) from the ``content`` domain, by context."""
    return translations(_active, "content").pgettext(context, message)


def N_(message: str) -> str:
    """Mark ``message`` for extraction without translating it yet (translated when shown)."""
    return message


def NN_(singular: str, plural: str) -> tuple[str, str]:
    """Mark a singular and plural pair for extraction (translated with ``ngettext``)."""
    return singular, plural
