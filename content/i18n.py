"""``_`` and ``N_`` for the simulator's and the content files' messages, in the platform's
active language.

``sim`` and ``content`` import nothing of ``autograder``, so they bind gettext here, over
the same ``messages`` catalogs (``locales/<lang>/LC_MESSAGES/messages.po``) that
``autograder i18n extract`` fills from ``sim/**.py`` and ``content/**.py`` too
(babel.cfg).  Whoever embeds the simulator says which language and where the
``locales/`` folder is: ``autograder.i18n`` calls :func:`set_language` whenever its own
language changes, with its own way of finding the folder.  ``AUTOGRADER_LOCALES``
overrides the folder, as it does for the platform.

A compiled ``.mo`` is used when it is at least as new as its ``.po``; otherwise the
``.po`` is compiled in memory with Babel, so a fresh clone needs no build step.
"""

from __future__ import annotations

import gettext as _gettext
import io
import os
from collections.abc import Callable
from functools import cache
from pathlib import Path

DOMAIN = "messages"
_CHECKOUT_LOCALES = Path(__file__).resolve().parent.parent / "locales"

_language = "en"
_find_locales: Callable[[], Path] | None = None


def set_language(lang: str, locales: Callable[[], Path] | None = None) -> None:
    """Translate later messages into ``lang``.

    ``locales`` finds the catalogs' folder; it is asked only when a message is translated,
    so setting the language never fails (the embedder's lookup may need a working
    directory).  Without it, the one given before, else ``locales/`` beside this package.
    """
    global _language, _find_locales
    _language = lang
    if locales is not None:
        _find_locales = locales


def get_language() -> str:
    return _language


def locales_dir() -> Path:
    env = os.environ.get("AUTOGRADER_LOCALES")
    if env:
        return Path(env)
    return _find_locales() if _find_locales else _CHECKOUT_LOCALES


def load_catalog(folder: Path, lang: str, domain: str = DOMAIN) -> _gettext.NullTranslations:
    """The ``domain`` catalog of ``lang`` in ``folder`` (``locales/<lang>/LC_MESSAGES``):
    its ``.mo`` if at least as new as its ``.po``, else the ``.po`` compiled in memory;
    a null catalog where there is neither. Read again when either file changes."""
    stamp = (_mtime(folder / f"{domain}.po"), _mtime(folder / f"{domain}.mo"))
    return _catalog(folder, lang, domain, stamp)


@cache
def _catalog(folder: Path, lang: str, domain: str,
             stamp: tuple[float, float]) -> _gettext.NullTranslations:
    po, mo = folder / f"{domain}.po", folder / f"{domain}.mo"
    if mo.exists() and stamp[1] >= stamp[0]:
        with mo.open("rb") as fh:
            return _gettext.GNUTranslations(fh)
    if not po.exists():
        return _gettext.NullTranslations()
    from babel.messages.mofile import write_mo
    from babel.messages.pofile import read_po

    with po.open("rb") as fh:
        catalog = read_po(fh, locale=lang, domain=domain)
    buffer = io.BytesIO()
    write_mo(buffer, catalog, use_fuzzy=False)
    buffer.seek(0)
    return _gettext.GNUTranslations(buffer)


def _mtime(path: Path) -> float:
    try:
        return path.stat().st_mtime
    except OSError:
        return -1.0


def translations(lang: str | None = None) -> _gettext.NullTranslations:
    """The active (or ``lang``'s) catalog; English, the source language, is a null one."""
    lang = lang or _language
    if lang == "en":
        return _gettext.NullTranslations()
    return load_catalog(locales_dir() / lang / "LC_MESSAGES", lang)


def _(message: str) -> str:
    """Translate ``message``; use named placeholders: ``_("{path}: ok").format(path=p)``."""
    return translations().gettext(message)


def ngettext(singular: str, plural: str, n: int) -> str:
    """Translate a message about ``n`` things (Urdu, like English, has two forms)."""
    return translations().ngettext(singular, plural, n)


def pgettext(context: str, message: str) -> str:
    """Translate ``message`` given in ``context`` (a world's title: context ``world``)."""
    return translations().pgettext(context, message)


def N_(message: str) -> str:
    """Mark ``message`` for extraction without translating it yet (translated when shown)."""
    return message


def NP_(context: str, message: str) -> str:
    """Mark ``message`` in ``context`` for extraction (translate it with :func:`pgettext`)."""
    return message
