"""The translation glossary (``locales/<lang>/glossary.yaml``) and what it checks.

A glossary gives each English term its one rendering in the language, with the reason, and
lists the renderings that must not appear.  :class:`Glossary` checks translated text
against it: a forbidden rendering, a term of the English with no rendering in the
translation (where the entry says the English implies one), and Latin words that would run
together into one left-to-right run.  Catalog entries, README lines and the comments in a
README's code blocks are checked; every finding is a :class:`~autograder.i18n.tools.Problem`
printed as ``file:line: message``.  The file format is described at the top of
``locales/ur/glossary.yaml``.

Two checks need no glossary and apply to every catalog: no obsolete (``#~``) entries and
no header left at gettext's template values (``FULL NAME``, ``YEAR-MO-DA``, ...).
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Literal

from babel.messages.catalog import Catalog, Message

from autograder.i18n import LANGUAGES, _, rules
from autograder.i18n.tools import Problem, check_catalog, read_catalog
from content import ContentError, Document, build, load_document

GLOSSARY_FILE = "glossary.yaml"
TRANSLATIONS = tuple(lang for lang in LANGUAGES if lang != "en")
"""The languages translated from English: what ``i18n check`` checks by default."""

# What a checked text is stripped of before matching: code spans and fenced code are code;
# placeholders become a number (so "{seconds} s" reads as a number and a unit); quoted
# English (a string the student must print) is code too.
_CODE_SPAN = re.compile(r"`[^`]*`")
_PLACEHOLDER = re.compile(r"\{\{|\}\}|\{[^{}]*\}|%\(\w+\)[sdrf]")
_QUOTED = re.compile(r"'[^'\u0600-\u06ff\n]*'|\"[^\"\u0600-\u06ff\n]*\"")
_LINK_TARGET = re.compile(r"\]\([^)]*\)")
# Code written without backticks: identifiers (snake_case, dotted, slashed such as
# agent/cmd_vel, m/s), command-line options with their value, and commands.
_IDENTIFIER = re.compile(r"\w*[A-Za-z]\w*(?:[./]\w+)+|\w*[A-Za-z]\w*_\w*|\w+\(\)"
                         r"|(?<![\w-])--?[A-Za-z][\w-]*(?: [^\s،۔؛]*:=[^\s،۔؛]*)?"
                         r"|\bautograder(?: [a-z][\w-]*)+")
_URDU = re.compile(r"[\u0600-\u06ff]")
_LATIN = re.compile(r"[A-Za-z]")
_LATIN_RUN = re.compile(r"[A-Za-z][\w.\-/+]*(?: [A-Za-z][\w.\-/+]*)+")
# کرنا and ہونا after a Latin verb ("publish کریں", "set نہیں ہوا"): the book's way of
# writing an API verb in an Urdu sentence.
_LIGHT_VERB = re.compile(r"\s*(?:(?:نہیں|بھی|تو) )?"
                         r"(?:کر|کیج|کی|کیا|کیے|کئے|ہو|ہوت|ہوئ|ہوا|ہوں|ہونے|ہونا)")
_KEEP = re.compile(r"glossary: keep ([^(:]+)")
_CODE_MARK = "§"

# gettext's template values: a header still holding one was never filled in.
_TEMPLATE_VALUES = ("FULL NAME", "EMAIL@ADDRESS", "YEAR-MO-DA", "HO:MI+ZONE", "ORGANIZATION",
                    "FIRST AUTHOR", "LL@li.org", "LANGUAGE <", "PACKAGE VERSION")
_TEMPLATE_VERSION = re.compile(r'^"Project-Id-Version: .*\bVERSION\\n"$')


@dataclasses.dataclass(frozen=True)
class Term:
    """One entry: an English term, its one rendering and what must not stand for it."""

    en: str
    ur: str
    why: str
    plural: str | None = None
    forms: tuple[str, ...] = ()
    gender: Literal["m", "f"] | None = None
    latin: bool = False
    forbid: tuple[str, ...] = ()
    allow: tuple[str, ...] = ()
    require: str | None = None
    oblique: str | None = None
    names: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        for name in ("en", "ur", "why"):
            if not getattr(self, name).strip():
                raise ValueError(_("{field}: must not be empty").format(field=name))

    @property
    def renderings(self) -> tuple[str, ...]:
        return tuple(r for r in (self.ur, self.plural, *self.forms) if r)


@dataclasses.dataclass(frozen=True)
class GlossaryFile:
    language: str
    terms: tuple[Term, ...]
    source: str = ""
    compounds: tuple[str, ...] = ()
    latin_verbs: tuple[str, ...] = ()


@dataclasses.dataclass(frozen=True)
class _Rule:
    term: Term
    line: int
    forbid: tuple[re.Pattern[str], ...]
    allow: tuple[re.Pattern[str], ...]
    require: re.Pattern[str] | None


def _normal(words: str) -> str:
    """A Latin run compared without case and plural s: "Callback groups" ~ "callback group"."""
    out = []
    for word in words.lower().split():
        if len(word) > 2 and word.endswith("s") and not word.endswith("ss"):
            word = word[:-1]
        out.append(word)
    return " ".join(out)


def _compile(doc: Document, pattern: str, *where: str | int) -> re.Pattern[str]:
    """A glossary's regular expression; a broken one names its file, line and field."""
    try:
        return re.compile(pattern)
    except re.error as exc:
        raise doc.error(_("not a regular expression: {error}").format(error=exc),
                        *where) from None


def prose(text: str) -> str:
    """``text`` as the checks read it: code, placeholders and quoted English taken out."""
    text = _LINK_TARGET.sub("]", text)
    text = _CODE_SPAN.sub(_CODE_MARK, text)
    text = _PLACEHOLDER.sub("0", text)
    text = _QUOTED.sub(_CODE_MARK, text)
    return _IDENTIFIER.sub(_CODE_MARK, text)


class Glossary:
    """A loaded glossary: compiled rules, each knowing its line in the file."""

    def __init__(self, path: Path, data: GlossaryFile, doc: Document) -> None:
        self.path = path
        self.language = data.language
        self.compounds = frozenset(_normal(c) for c in data.compounds)
        self.verbs = frozenset(v.lower() for v in data.latin_verbs)
        self.rules: list[_Rule] = []
        self.gendered = tuple(
            (word, term.gender, term.en) for term in data.terms if term.gender
            for word in (term.ur, *term.names) if " " not in word)
        self.oblique = tuple((term.ur, term.oblique) for term in data.terms if term.oblique)
        self.nouns = frozenset(word for term in data.terms if term.gender and not term.latin
                               for word in term.renderings)
        for i, term in enumerate(data.terms):
            self.rules.append(_Rule(
                term, doc.line("terms", i) or 1,
                tuple(_compile(doc, p, "terms", i, "forbid", j)
                      for j, p in enumerate(term.forbid)),
                tuple(_compile(doc, p, "terms", i, "allow", j)
                      for j, p in enumerate(term.allow)),
                _compile(doc, term.require, "terms", i, "require") if term.require else None))

    @property
    def terms(self) -> list[Term]:
        return [r.term for r in self.rules]

    # --- one text -------------------------------------------------------------------
    def problems(self, text: str, at: tuple[Path, int], en: str | None = None,
                 keep: Iterable[str] = (), before: str = "", grammar: bool = True
                 ) -> Iterator[Problem]:
        """Problems of one translated ``text`` (``en``: its English, for ``require``;
        ``before``: the end of the line before, when the text continues it; ``grammar``:
        run the rules that read a whole sentence, which a README runs per paragraph)."""
        file, line = at
        kept = tuple(keep)
        ur = prose(text)
        for rule in self.rules:
            if any(rule.term.en.startswith(k) for k in kept):
                continue
            checked = ur
            for allowed in rule.allow:
                checked = allowed.sub(_CODE_MARK, checked)
            for pattern in rule.forbid:
                found = pattern.search(checked)
                if found:
                    yield Problem(file, line, _(
                        "{lang}: {found!r} goes against the glossary's {term!r} "
                        "({glossary}:{line}): write {ur}").format(
                        lang=self.language, found=found.group(0), term=rule.term.en,
                        glossary=self.path, line=rule.line, ur=rule.term.ur))
                    break
            if en is not None and rule.require is not None and rule.require.search(prose(en)):
                if not any(r in ur for r in rule.term.renderings):
                    yield Problem(file, line, _(
                        "{lang}: the English says {term!r} but the translation has none of "
                        "{renderings} ({glossary}:{line})").format(
                        lang=self.language, term=rule.term.en,
                        renderings=", ".join(rule.term.renderings), glossary=self.path,
                        line=rule.line))
        yield from self._latin_runs(ur, file, line, prose(before))
        if grammar:
            yield from self.grammar(text, file, [line])

    def grammar(self, text: str, file: Path, lines: list[int | None],
                starts: list[int] | None = None) -> Iterator[Problem]:
        """The language rules of :mod:`autograder.i18n.rules` on one translated text (a
        README's paragraph: ``lines`` and the offsets where they ``starts`` in it)."""
        found = [*rules.code_outside_spans(text, translated=True),
                 *rules.polite_imperatives(prose(text)),
                 *rules.tense_clashes(prose(text)),
                 *rules.agreement(text, self.gendered, self.nouns),
                 *rules.direct_before_postposition(text, self.oblique)]
        for what, message in found:
            at = text.find(what.split()[0]) if what.split() else -1
            index = sum(1 for start in starts or [0] if start <= max(at, 0)) - 1
            yield Problem(file, lines[index], f"{self.language}: {message}")

    def _across_lines(self, path: Path, paragraph: list[tuple[int, str]]) -> list[Problem]:
        """Forbidden renderings split over two lines of a paragraph ("call" ending one
        line, "کرتا" starting the next), which the line-by-line check cannot see."""
        problems = []
        for rule in self.rules:
            texts = []
            for _n, text in paragraph:
                checked = prose(text.strip())
                for allowed in rule.allow:
                    checked = allowed.sub(_CODE_MARK, checked)
                texts.append(checked)
            ends = [sum(len(t) + 1 for t in texts[:i + 1]) - 1 for i in range(len(texts))]
            joined = " ".join(texts)
            for pattern in rule.forbid:
                for found in pattern.finditer(joined):
                    line = next(i for i, end in enumerate(ends) if found.start() < end)
                    if found.end() > ends[line]:
                        problems.append(Problem(path, paragraph[line][0], _(
                            "{lang}: {found!r} goes against the glossary's {term!r} "
                            "({glossary}:{line}): write {ur}").format(
                            lang=self.language, found=found.group(0), term=rule.term.en,
                            glossary=self.path, line=rule.line, ur=rule.term.ur)))
        return problems

    def _latin_runs(self, ur: str, file: Path, line: int, before: str = "") -> Iterator[Problem]:
        if not _URDU.search(ur):
            return  # a line with no Urdu at all (a table rule, a bare name) runs no risk
        # A paragraph's lines join with a space: a Latin word ending the line before and
        # one starting this line are one run too.
        tail = re.search(r"[A-Za-z][\w.\-/+]*$", before.rstrip())
        text = f"{tail.group(0)} {ur}" if tail and _LATIN.match(ur) else ur
        for match in _LATIN_RUN.finditer(text):
            words = match.group(0).split()
            if words[-1].lower() in self.verbs and _LIGHT_VERB.match(text, match.end()):
                words = words[:-1]
            if len(words) < 2 or _normal(" ".join(words)) in self.compounds:
                continue
            yield Problem(file, line, _(
                "{lang}: Latin words run together into one left-to-right run: {run!r}; "
                "put an Urdu word between them, or list the term under compounds in "
                "{glossary}").format(lang=self.language, run=" ".join(words),
                                     glossary=self.path))

    # --- catalogs and READMEs ------------------------------------------------------------
    def check_catalog(self, po: Path) -> list[Problem]:
        """Every translated entry of ``po``."""
        try:
            catalog = read_catalog(po, self.language)
        except ContentError as exc:
            return [Problem(exc.path, exc.line, exc.message)]
        lines = po.read_text(encoding="utf-8").splitlines()
        problems: list[Problem] = []
        for message in catalog:
            if message.id:
                problems += self.check_message(po, message, lines)
        return problems

    def check_message(self, po: Path, message: Message, lines: list[str]) -> list[Problem]:
        """One catalog entry (``lines``: the catalog's text, to point at its msgstr); a
        translator comment "glossary: keep <en>" exempts it from that term."""
        ids = message.id if isinstance(message.id, tuple) else (message.id,)
        strs = message.string if isinstance(message.string, tuple) else (message.string,)
        keep = [m.group(1).strip() for c in message.user_comments
                if (m := _KEEP.match(c.strip()))]
        line = _msgstr_line(lines, message.lineno)
        problems: list[Problem] = []
        for i, text in enumerate(strs):
            if text:
                english = ids[min(i, len(ids) - 1)]
                problems += self.problems(text, (po, line), english, keep)
        for english in ids:
            problems += [Problem(po, message.lineno, _("the English: {message}").format(
                message=found)) for _code, found in rules.code_outside_spans(
                    english, translated=False)]
        return problems

    def check_readme(self, path: Path) -> list[Problem]:
        """Prose lines of a README and the comments in its code blocks."""
        try:
            lines = path.read_text(encoding="utf-8").splitlines()
        except OSError as exc:
            return [Problem(path, None, _("cannot read file: {error}").format(error=exc))]
        problems: list[Problem] = []
        body = [n for n, text in enumerate(lines, 1) if text.strip()]
        if not body or lines[body[0] - 1].strip() != RTL_OPEN \
                or lines[body[-1] - 1].strip() != "</div>":
            problems.append(Problem(path, body[0] if body else 1, _(
                "a right-to-left README is wrapped in {open} ... </div> (with a blank line "
                "after the opening tag), so GitHub lays it out right to left").format(
                    open=RTL_OPEN)))
        fenced = False
        previous = ""
        paragraph: list[tuple[int, str]] = []

        def sentences() -> list[Problem]:
            """The grammar of the paragraph read so far, its lines joined."""
            joined, starts = "", []
            for _n, line_text in paragraph:
                starts.append(len(joined))
                joined += line_text.strip() + " "
            found = list(self.grammar(joined, path, [n for n, _t in paragraph], starts))
            found += self._across_lines(path, paragraph)
            paragraph.clear()
            return found

        for n, text in enumerate(lines, 1):
            if HTML_WRAPPER.match(text):
                continue
            if text.lstrip().startswith("```"):
                fenced = not fenced
                previous = ""
                problems += sentences()
                continue
            if not fenced:
                continues = previous and not re.match(r"\s*(?:[-*|#]|\d+\.)\s", text + " ")
                if not continues or not text.strip():
                    problems += sentences()
                if text.strip():
                    paragraph.append((n, text.strip().strip("|").replace("|", "،")))
                start = rules.block_starts_latin(text) if not continues and text.strip() \
                    else None
                if start is not None:
                    problems.append(Problem(path, n, _(
                        "{lang}: this block starts with a Latin word ({start!r}), so GitHub "
                        "lays it out left to right: start it with an Urdu word").format(
                        lang=self.language, start=start)))
                problems += self.problems(text, (path, n), before=previous if continues else "",
                                          grammar=False)
                previous = text if text.strip() and not text.lstrip().startswith(("|", "#")) \
                    else ""
                continue
            comment = code_comment(text)
            if comment is None:
                continue
            if _LATIN.search(prose(comment)) and not _URDU.search(comment):
                problems.append(Problem(path, n, _(
                    "{lang}: a comment in a code block is not translated: {comment!r}").format(
                    lang=self.language, comment=comment)))
            problems += self.problems(comment, (path, n))
        problems += sentences()
        problems.sort(key=lambda p: p.line or 0)
        return problems


def code_comment(line: str) -> str | None:
    """The comment of a shell or Python line (or a one-line docstring), if it has one."""
    stripped = line.strip()
    if stripped.startswith("#!"):
        return None
    doc = re.fullmatch(r'[rRbBuU]?"""(.*)"""', stripped)
    if doc:
        return doc.group(1).strip()
    quote = None
    for i, ch in enumerate(line):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (i == 0 or line[i - 1].isspace()):
            return line[i + 1:].strip()
    return None


def _msgstr_line(lines: list[str], msgid_line: int | None) -> int | None:
    """The line of the ``msgstr`` that belongs to the msgid on ``msgid_line``."""
    if not msgid_line:
        return None
    for n in range(msgid_line - 1, len(lines)):
        if lines[n].startswith("msgstr"):
            return n + 1
    return msgid_line


def load_glossary(path: Path) -> Glossary:
    """Read and check a glossary; a malformed one is a ContentError naming file:line."""
    doc = load_document(path)
    data = build(GlossaryFile, doc, doc.data)
    return Glossary(path, data, doc)


def glossary_for(locales: Path, lang: str) -> Glossary | None:
    """The glossary of ``lang`` under ``locales``, or None when there is none."""
    path = locales / lang / GLOSSARY_FILE
    return load_glossary(path) if path.exists() else None


# --- checks that need no glossary -------------------------------------------------------
def housekeeping(po: Path) -> list[Problem]:
    """Obsolete ``#~`` entries and header fields left at gettext's template values."""
    try:
        lines = po.read_text(encoding="utf-8").splitlines()
    except OSError as exc:
        return [Problem(po, None, _("cannot read file: {error}").format(error=exc))]
    problems: list[Problem] = []
    in_header = True
    for n, text in enumerate(lines, 1):
        if in_header:
            if text.startswith("#:") or (text.startswith("msgid ") and text != 'msgid ""'):
                in_header = False
            else:
                template = next((v for v in _TEMPLATE_VALUES if v in text), None)
                if template is None and _TEMPLATE_VERSION.match(text):
                    template = "VERSION"
                if template is not None:
                    problems.append(Problem(po, n, _(
                        "the header still holds the template value {value!r}: fill it in")
                        .format(value=template)))
        if text.startswith("#~ msgid"):
            problems.append(Problem(po, n, _(
                "obsolete entry (#~): its English is no longer in the template; delete it")))
    return problems


# GitHub lays a Markdown file out left to right, paragraph by paragraph (dir=auto): an
# Urdu paragraph that starts with a Latin word would show left to right. A wrapping div
# (Markdown still works inside it after a blank line) sets the direction for the whole.
RTL_OPEN = '<div dir="rtl" lang="ur">'
HTML_WRAPPER = re.compile(r"\s*</?div\b[^>]*>\s*$")


def title_problem(path: Path, lang: str, title: str) -> Problem | None:
    """A README whose first heading is not the exercise's title in the catalog."""
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except OSError as exc:
        return Problem(path, None, _("cannot read file: {error}").format(error=exc))
    line, found = next(((n, s[2:].strip()) for n, s in enumerate(lines, 1)
                        if s.startswith("# ")), (1, ""))
    if found == title:
        return None
    return Problem(path, line, _(
        "{lang}: the title {found!r} is not the catalog's title of the exercise, "
        "{expected!r}").format(lang=lang, found=found, expected=title))


def check_language(locales: Path, lang: str, root: Path | None) -> list[Problem]:
    """Everything beyond completeness for one language: no obsolete entries or template
    headers in its catalogs; with a glossary, every catalog entry and every exercise
    README against it; each README's title as the content catalog translates it."""
    pos = sorted((locales / lang / "LC_MESSAGES").glob("*.po"))
    problems: list[Problem] = []
    for po in pos:
        problems += housekeeping(po)
    try:
        glossary = glossary_for(locales, lang)
    except ContentError as exc:
        problems.append(as_problem(exc))
        glossary = None
    if glossary is not None:
        for po in pos:
            problems += glossary.check_catalog(po)
    content = locales / lang / "LC_MESSAGES" / "content.po"
    try:
        catalog = read_catalog(content, lang) if content.exists() else None
    except ContentError:
        catalog = None  # reported by the completeness check
    for exercise, readme in readme_paths(root, lang) if root else []:
        title = exercise_title(catalog, exercise)
        if title is not None and (problem := title_problem(readme, lang, title)):
            problems.append(problem)
        if glossary is not None:
            problems += glossary.check_readme(readme)
    return problems


def as_problem(exc: ContentError) -> Problem:
    message = f"{exc.field}: {exc.message}" if exc.field else exc.message
    return Problem(exc.path, exc.line, message)


def readme_paths(root: Path, lang: str) -> list[tuple[str, Path]]:
    """Every exercise's README in ``lang``: (exercise id, path)."""
    folder = root / "assignments"
    if not folder.is_dir():
        return []
    return [(p.parent.name, p) for p in sorted(folder.glob(f"*/README.{lang}.md"))]


def exercise_title(catalog: Catalog | None, exercise: str) -> str | None:
    """The translated title of ``exercise`` in a content catalog, if it has one."""
    if catalog is None:
        return None
    for message in catalog:
        if message.context == f"exercise:{exercise}:title" and message.string:
            return str(message.string)
    return None


def check_all(locales: Path, langs: tuple[str, ...] = TRANSLATIONS,
              root: Path | None = None) -> list[Problem]:
    """What ``i18n check`` finds: each template's entries translated in each language, and
    the language rules (glossary, grammar, READMEs) of :func:`check_language`."""
    problems: list[Problem] = []
    for template in sorted(locales.glob("*.pot")):
        for lang in langs:
            po = locales / lang / "LC_MESSAGES" / f"{template.stem}.po"
            problems += check_catalog(template, po, lang)
    for lang in langs:
        problems += check_language(locales, lang, root)
    return problems
