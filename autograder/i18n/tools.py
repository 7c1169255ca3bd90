"""Extract, update, compile and check gettext catalogs, with Babel's library API.

Two domains: ``messages`` (what the platform prints: Python and Jinja templates) and
``content`` (course content: quiz files and exercise titles and summaries).  ``babel.cfg``
says which extractor reads which files; its python and jinja2 sections feed
``messages``, the others feed ``content``.
"""

from __future__ import annotations

import dataclasses
import io
import re
from collections.abc import Iterable, Iterator
from pathlib import Path

from babel.messages.catalog import Catalog, Message
from babel.messages.extract import DEFAULT_KEYWORDS, extract_from_dir
from babel.messages.frontend import parse_mapping_cfg
from babel.messages.mofile import write_mo
from babel.messages.pofile import PoFileError, read_po, write_po

from autograder.i18n import _
from content import ContentError

PLATFORM_DOMAIN = "messages"
CONTENT_DOMAIN = "content"
PLATFORM_METHODS = frozenset({"python", "jinja2", "autograder.i18n.label_extract:extract_tests",
                              "sim.worldfile:extract_world"})
KEYWORDS = {**DEFAULT_KEYWORDS, "N_": None, "NP_": ((1, "c"), 2), "NN_": (1, 2)}
COMMENT_TAGS = ("TRANSLATORS:",)
PROJECT = "rclpy-autograder"

_PLACEHOLDER = re.compile(r"\{[A-Za-z_][\w]*(?:![rsa])?(?::[^{}]*)?\}|%\(\w+\)[sdrf]")
_CODE = re.compile(r"`[^`]+`")




@dataclasses.dataclass(frozen=True)
class Problem:
    """One lint finding, printed as ``path:line: message``."""

    path: Path
    line: int | None
    message: str

    def __str__(self) -> str:
        return f"{self.path}:{self.line or 1}: {self.message}"


def read_mapping(cfg: Path) -> tuple[list[tuple[str, str]], dict[str, dict[str, str]]]:
    try:
        with cfg.open(encoding="utf-8") as fh:
            return parse_mapping_cfg(fh, str(cfg))
    except FileNotFoundError:
        raise ContentError(cfg, _("file not found")) from None
    except Exception as exc:  # configparser raises several kinds
        raise ContentError(cfg, _("cannot read the mapping: {error}").format(
            error=str(exc).splitlines()[0])) from None


def domain_of(method: str) -> str:
    return PLATFORM_DOMAIN if method in PLATFORM_METHODS else CONTENT_DOMAIN


def _collect(root: Path, method_map: list[tuple[str, str]],
             options_map: dict[str, dict[str, str]], domain: str) -> Catalog:
    catalog = Catalog(project=PROJECT, domain=domain, fuzzy=False,
                      msgid_bugs_address="", copyright_holder="")
    mapping = [(p, m) for p, m in method_map if domain_of(m) == domain]
    try:
        for filename, lineno, message, comments, context in extract_from_dir(
                root, mapping, options_map, keywords=KEYWORDS, comment_tags=COMMENT_TAGS,
                strip_comment_tags=True):
            catalog.add(message, None, [(filename, lineno)], auto_comments=comments,
                        context=context)
    except Exception as exc:
        # A quiz or exercise file that does not load names itself; other errors too.
        raise ContentError(root, _("extraction failed: {error}").format(error=exc)) from None
    return catalog


def extract(root: Path, locales: Path, cfg: Path | None = None) -> list[Path]:
    """Write ``messages.pot`` and ``content.pot`` under ``locales``; return their paths."""
    method_map, options_map = read_mapping(cfg or root / "babel.cfg")
    written = []
    for domain in (PLATFORM_DOMAIN, CONTENT_DOMAIN):
        catalog = _collect(root, method_map, options_map, domain)
        out = locales / f"{domain}.pot"
        out.parent.mkdir(parents=True, exist_ok=True)
        buffer = io.BytesIO()
        write_po(buffer, catalog, width=88, sort_by_file=True, omit_header=False,
                 include_lineno=_with_lines(domain))
        if not out.exists() or _stamp_free(out.read_bytes()) != _stamp_free(buffer.getvalue()):
            out.write_bytes(buffer.getvalue())  # unchanged: its date and the .po files stay
        written.append(out)
    return written


def _with_lines(domain: str) -> bool:
    """Line numbers in locations: for course content (a quiz's own lines move only when it
    changes), not for the platform, whose every edit would move other strings' lines and
    rewrite entries whose text did not change: file-only locations keep those still."""
    return domain != PLATFORM_DOMAIN


_STAMP = re.compile(rb'^"POT-Creation-Date: [^"]*"\n', re.M)


def _stamp_free(text: bytes) -> bytes:
    return _STAMP.sub(b"", text)


def read_catalog(path: Path, locale: str | None = None) -> Catalog:
    """Read a ``.po`` or ``.pot`` strictly: a syntax error names the file and line."""
    try:
        with path.open("rb") as fh:
            return read_po(fh, locale=locale, abort_invalid=True)
    except FileNotFoundError:
        raise ContentError(path, _("file not found")) from None
    except PoFileError as exc:
        message = str(exc).rsplit(" on ", 1)[0]
        raise ContentError(path, _("malformed catalog: {problem}").format(problem=message),
                           exc.lineno) from None
    except (ValueError, UnicodeDecodeError) as exc:
        raise ContentError(path, _("malformed catalog: {problem}").format(problem=exc)) from None


def _write(path: Path, catalog: Catalog) -> None:
    buffer = io.BytesIO()
    write_po(buffer, catalog, width=88, sort_by_file=True,
             include_lineno=_with_lines(catalog.domain or path.stem))
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(buffer.getvalue())


def update(locales: Path, languages: Iterable[str]) -> list[Path]:
    """Merge each template into ``<lang>/LC_MESSAGES/<domain>.po`` (creating it if new).

    Changed English strings become fuzzy (lint fails on them until a translator checks
    them); strings no longer in the template become obsolete ``#~`` entries.
    """
    written = []
    for template_path in sorted(locales.glob("*.pot")):
        template = read_catalog(template_path)
        domain = template_path.stem
        for lang in languages:
            po = locales / lang / "LC_MESSAGES" / f"{domain}.po"
            if po.exists():
                catalog = read_catalog(po, lang)
                catalog.update(template, update_header_comment=False)
            else:
                catalog = Catalog(locale=lang, domain=domain, project=PROJECT)
                catalog.update(template)
                catalog.fuzzy = False
            _write(po, catalog)
            written.append(po)
    return written


def compile_catalogs(locales: Path) -> list[Path]:
    """Write a ``.mo`` beside every ``.po`` (fuzzy entries left out)."""
    written = []
    for po in sorted(locales.glob("*/LC_MESSAGES/*.po")):
        catalog = read_catalog(po, po.parent.parent.name)
        mo = po.with_suffix(".mo")
        with mo.open("wb") as fh:
            write_mo(fh, catalog, use_fuzzy=False)
        written.append(mo)
    return written


def placeholders(text: str) -> list[str]:
    """Named placeholders and code spans: what a translation must keep unchanged."""
    return sorted(_PLACEHOLDER.findall(text) + _CODE.findall(text))


def check_message(path: Path, lang: str, message: Message | None, where: str,
                  at: tuple[Path, int | None] | None = None) -> Iterator[Problem]:
    """Problems with one translated entry: missing, empty, fuzzy, placeholders changed."""
    file, line = at or (path, message.lineno if message else None)
    if message is None or not message.string or (
            isinstance(message.string, tuple) and not all(message.string)):
        yield Problem(file, line, _("{lang}: no translation of {where} in {catalog}").format(
            lang=lang, where=where, catalog=path))
        return
    if message.fuzzy:
        yield Problem(file, line, _("{lang}: the translation of {where} is fuzzy "
                                    "(check it, then remove the fuzzy flag) in {catalog}")
                      .format(lang=lang, where=where, catalog=f"{path}:{message.lineno}"))
    ids = message.id if isinstance(message.id, tuple) else (message.id,)
    strs = message.string if isinstance(message.string, tuple) else (message.string,)
    # A plural entry's forms may each keep the singular's or the plural's placeholders
    # ("This core test failed" names no {count}).
    allowed = [placeholders(i) for i in ids]
    expected = allowed[-1]
    for s in strs:
        if placeholders(s) not in allowed:
            yield Problem(file, line, _("{lang}: the translation of {where} changes its "
                                        "placeholders or code: {expected} became {found} "
                                        "in {catalog}").format(
                lang=lang, where=where, expected=" ".join(expected) or "-",
                found=" ".join(placeholders(s)) or "-", catalog=f"{path}:{message.lineno}"))
            break


def check_catalog(template_path: Path, po: Path, lang: str) -> list[Problem]:
    """Every entry of a template translated, not fuzzy, with the same placeholders."""
    try:
        template = read_catalog(template_path)
        catalog = read_catalog(po, lang)
    except ContentError as exc:
        return [Problem(exc.path, exc.line, exc.message)]
    problems = []
    for entry in template:
        if not entry.id:
            continue
        where = repr(entry.id if isinstance(entry.id, str) else entry.id[0])
        found = catalog.get(entry.id, context=entry.context)
        problems.extend(check_message(po, lang, found, where,
                                      at=(po, found.lineno if found else None)))
    return problems
