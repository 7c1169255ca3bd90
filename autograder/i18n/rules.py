"""Language rules a reader of a right-to-left translation catches and a glossary entry alone
cannot: code written outside a code span, agreement with a gendered term, the oblique case
before a postposition, the imperative's register, and a README block that starts with a
Latin word.  Each rule is a function of one text returning ``(found, message)`` pairs;
:class:`~autograder.i18n.glossary.Glossary` turns them into ``file:line`` problems.
"""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Iterable, Iterator

from autograder.i18n import _

CODE_SPAN = re.compile(r"`[^`]*`")
_PLACEHOLDER = re.compile(r"\{\{|\}\}|\{[^{}]*\}|%\(\w+\)[sdrf]")

# --- code outside a code span ------------------------------------------------------------
# In right-to-left text, Latin pieces separated by operators, brackets or commas are laid
# out as separate left-to-right runs in right-to-left order: "range_min <= r <= range_max"
# reads "range_max => r => range_min".  Code is written `as one span`.
_FIELD = r"\{[A-Za-z_]\w*(?:![rsa])?(?::[^{}]*)?\}"
_TOKEN = rf"(?:[A-Za-z_][\w.]*|\d[\w.]*|{_FIELD})"
_OPERAND = rf"(?:[A-Za-z]\w*_[\w.]*|[a-z]{{1,2}}|\d[\d.]*|{_FIELD})"
_CODE_SHAPES = (
    # an operator between two operands: "r <= range_max", "angle_max - angle_min"
    re.compile(rf"{_TOKEN}[)\]]* (?:<=|>=|==|!=|<|>|\+|-|\*|/|//|%) [(\[-]*{_TOKEN}"),
    # name=value: "success=true", "angular.z=0"
    re.compile(r"(?:\b[A-Za-z_][\w.]*|\{[A-Za-z_]\w*\})=[-+]?(?:[\w.'\"]+|\{\w+\})"),
    # a call with arguments: "len(ranges)", "get_logger().error(...)"
    re.compile(r"\b[A-Za-z_][\w.]*\((?=[^()\u0600-\u06ff]*[\w.'\"])[^()\u0600-\u06ff]*\)"),
    # a pair or an interval: "(goal_x, goal_y)", "[-pi, pi]", "[{low}, {high}]" (not a
    # list of names: "(rosbag2, MCAP)")
    re.compile(rf"[(\[] ?[-+]?{_OPERAND}(?:, ?[-+]?{_OPERAND})+ ?[)\]]"),
)
# In Urdu text a Latin comma between Latin words joins them into one run.
_LATIN_COMMA = re.compile(rf"{_TOKEN}['\")\]]*, ['\"(\[+-]*{_TOKEN}")


def code_outside_spans(text: str, translated: bool) -> Iterator[tuple[str, str]]:
    """Expressions, calls, pairs, intervals and ``name=value`` written outside a code span
    (in a translation also Latin words joined by a Latin comma)."""
    bare = CODE_SPAN.sub(" § ", text)
    shapes = (*_CODE_SHAPES, _LATIN_COMMA) if translated else _CODE_SHAPES
    for shape in shapes:
        found = shape.search(bare)
        if found:
            yield found.group(0), _(
                "code outside a code span: write {code} between backticks, so that it is "
                "laid out as one left-to-right run").format(code=repr(found.group(0)))
            return


# --- imperatives -----------------------------------------------------------------------
# The book and the catalogs address the student with the -یں imperative ("چلائیں،
# لکھیں"); the polite -یے form (چلائیے، لکھیے، کیجیے) is another register.
_IMPERATIVE = re.compile(r"(?<!\w)([\u0600-\u06ff]+(?:یے|ئیے|یئے|ئے))(?!\w)")
_NOT_IMPERATIVE = frozenset({
    "لیے", "لئے", "چاہیے", "چاہئے", "کیے", "کئے", "دیے", "دئے", "زاویے", "گئے", "نئے",
    "ہوئے", "پیے", "جیے", "سیے", "لیئے", "ہوے", "رہے", "سکے", "چکے", "بیٹھے", "ملے",
    "جائے", "کرایے", "رویے", "سایے", "پایے",
})
_POLITE = re.compile(r"(?:یجیے|یجئے|ئیے|یئے|یے)$")


# A "when" clause in the present or subjunctive ("جب ... ہو،") whose sentence ends in the
# past ("... تھا۔"): fragments spliced from two messages, each in its own tense.
_TENSE_CLASH = re.compile(r"جب[^۔\n]*?\s(?:ہو|ہوں|ہے|ہیں)(?:،|\s)[^۔\n]*?\s(?:تھا|تھی|تھے)"
                          r"(?=\s*(?:۔|$))")


def tense_clashes(text: str) -> Iterator[tuple[str, str]]:
    """Sentences whose "when" clause is in the present and whose main verb is in the past."""
    for match in _TENSE_CLASH.finditer(text):
        yield match.group(0), _("a present \"when\" clause with a past main verb (tense "
                                "clash): {text!r}").format(text=match.group(0))


def polite_imperatives(text: str) -> Iterator[tuple[str, str]]:
    """Imperatives in the polite -یے form (the subjunctive -ائے of "جو وہ چلائے" is not one)."""
    for match in _IMPERATIVE.finditer(text):
        word = match.group(1)
        if word in _NOT_IMPERATIVE or not _POLITE.search(word) or word.endswith("ائے"):
            continue
        yield word, _("the polite imperative {word!r}: the book and the catalogs write the "
                      "-یں form ({plain})").format(word=word, plain=plain_imperative(word))


def plain_imperative(word: str) -> str:
    """The -یں imperative of a polite one: کیجیے → کریں، دیجیے → دیں، لکھیے → لکھیں."""
    special = {"کیجیے": "کریں", "کیجئے": "کریں", "دیجیے": "دیں", "دیجئے": "دیں",
               "لیجیے": "لیں", "لیجئے": "لیں", "پیجیے": "پییں"}
    if word in special:
        return special[word]
    return _POLITE.sub(lambda m: "ئیں" if m.group(0) in ("ئیے", "یئے") else "یں", word)


# --- agreement with a gendered term ----------------------------------------------------
_POSTPOSITION = ("کا", "کی", "کے", "کو", "میں", "سے", "پر", "نے", "تک", "والا", "والی",
                 "والے", "جیسا", "جیسی", "جیسے")
# A clause ends at Urdu punctuation and before the words that open another clause.
_CLAUSE_END = re.compile(r"[،؛۔:؟!\n()]|\s(?:جو|جس|جب|تو|کہ|کیونکہ|لیکن|مگر|اگر|تاکہ|جبکہ"
                         r"|یعنی|بعد|پہلے)\s")
# What may stand before a subject in its clause: particles, determiners, and adverbial
# phrases that end in a postposition ("کھلی جگہ میں check_path ...").
_LEAD = re.compile(r"^(?:.*\s(?:میں|پر|سے|تک|بعد|پہلے|ساتھ|لیے|بغیر|دوران|اندر|باہر))?\s*"
                   r"(?:(?:یہ|وہ|پھر|اب|تب|بھی|ہر|ایک|کوئی|کسی|وہی|یہی|نہ|ہی|§|0)\s+"
                   r"|\S+ (?:کا|کی|کے) )*$")
# A verb form by its ending (دیتا، کرے گی) or, short ones, as a whole word (دی, not خالی).
_MASCULINE_VERB = re.compile(r"(?:تا|گا|سکا|رہا|چکا|ہوا|گیا)$|^(?:دیا|لیا|پایا|تھا)$")
_FEMININE_VERB = re.compile(r"(?:تی|گی|سکی|رہی|چکی|ہوئی|گئی)$|^(?:دی|لی|پائی|تھی)$")
_LIGHT_VERB = re.compile(r"(?:کر|کیا|کیے)")
_AUXILIARY = frozenset({"ہے", "ہیں", "تھا", "تھی", "تھے", "ہو", "ہوں", "گا", "گی", "گے"})
_NOUNS_LOOKING_LIKE_VERBS = frozenset({"گنتی", "کشتی", "ہستی", "پتا", "ساتھی", "لی", "دی",
                                       "کی", "کیا", "والا", "والی", "سیدھا", "زیادہ", "ٹھیک",
                                       "وقتی", "بیتی", "رہا"})


def _verb_gender(clause: str) -> tuple[str, str] | None:
    """The gender of the clause's first finite verb form and the form, if it shows one."""
    words = clause.split()
    for i, word in enumerate(words):
        if word.endswith("نے"):
            return None  # an ergative subject, or the noun is an infinitive's object
        if word in _NOUNS_LOOKING_LIKE_VERBS and not (
                word in ("کیا", "دی", "لی", "رہا") and i and words[i - 1] not in _POSTPOSITION):
            continue
        following = words[i + 1] if i + 1 < len(words) else None
        finite = following is None or following in _AUXILIARY or word.endswith(
            ("گا", "گی", "سکا", "سکی", "چکا", "چکی"))
        if not finite:
            continue
        if _MASCULINE_VERB.search(word):
            return "m", word
        if _FEMININE_VERB.search(word):
            return "f", word
    return None


def agreement(text: str, nouns: Iterable[tuple[str, str, str]],
              other_nouns: frozenset[str] = frozenset()) -> Iterator[tuple[str, str]]:
    """Verbs and genitives that disagree with a gendered noun (``nouns``: (word, gender,
    the term's English) for each rendering and each name that stands for a term).

    A noun is taken as the subject of its clause when it opens the clause (after particles
    and adverbial phrases) and no postposition follows it; the clause's first finite verb
    then carries its gender.  A genitive before the noun carries its gender too (کی
    service، کا timer).  A noun that ``other_nouns`` (or a Latin word) follows qualifies
    that noun ("Python پروسیس") and is left alone."""
    bare = _PLACEHOLDER.sub("0", CODE_SPAN.sub(lambda m: m.group(0).strip("`"), text))
    bare = re.sub(r"\([^()]*\)", " ", bare)  # a parenthesis interrupts, it ends no clause
    for word, gender, en in nouns:
        noun = re.compile(rf"(?<![\w./-]){re.escape(word)}(?![\w./-])")
        for found in noun.finditer(bare):
            after = bare[found.end():].split()
            next_word = after[0] if after else ""
            # genitive: "کا service" but not "کا service call" (the head is call)
            before = bare[:found.start()].split()
            head = not re.match(r"[A-Za-z]", next_word) and next_word not in other_nouns
            if before and head and next_word not in ("والا", "والی", "والے"):
                wrong = "کا" if gender == "f" else "کی"
                if before[-1] == wrong or (gender == "f" and before[-1] == "کے"
                                           and next_word not in _POSTPOSITION):
                    yield f"{before[-1]} {word}", _(
                        "{found!r}: {term!r} is {gender} in the glossary, and its genitive "
                        "agrees").format(found=f"{before[-1]} {word}", term=en,
                                         gender=_gender_name(gender))
            if next_word in _POSTPOSITION or not head or _LIGHT_VERB.match(next_word):
                continue  # not the subject: a postposition's, or a compound verb's (جانچ کرنا)
            start = max((m.end() for m in _CLAUSE_END.finditer(bare, 0, found.start())),
                        default=0)
            if not _LEAD.match(bare[start:found.start()]):
                continue
            end = _CLAUSE_END.search(bare, found.end())
            clause = bare[found.end():end.start() if end else len(bare)]
            verb = _verb_gender(clause)
            if verb and verb[0] != gender:
                yield f"{word} … {verb[1]}", _(
                    "{found!r}: {term!r} is {gender} in the glossary, and the verb of its "
                    "clause agrees").format(found=f"{word} … {verb[1]}", term=en,
                                            gender=_gender_name(gender))


def _gender_name(gender: str) -> str:
    return _("masculine") if gender == "m" else _("feminine")


# --- the oblique case ----------------------------------------------------------------
_OBLIQUE_BEFORE = r"(?:سے|نے|کا|کی|کے|کو|میں|پر|تک)"


def direct_before_postposition(text: str, forms: Iterable[tuple[str, str]]
                               ) -> Iterator[tuple[str, str]]:
    """A noun in the direct case (ڈبہ، دائرہ، کمرہ) before a postposition, a number or a
    name between them ("ڈبہ 2 سے" for "ڈبے 2 سے"); ``forms``: (direct, oblique) pairs."""
    bare = _PLACEHOLDER.sub("0", CODE_SPAN.sub("§", text))
    for direct, oblique in forms:
        shape = re.compile(rf"(?<!\w){re.escape(direct)}"
                           rf"((?: (?:[-+]?\d[\d.]*|§|[A-Za-z_]\w*))? {_OBLIQUE_BEFORE})"
                           r"(?!\w)")
        found = shape.search(bare)
        if found:
            yield found.group(0), _(
                "{found!r}: a postposition takes the oblique case, {oblique}").format(
                found=found.group(0), oblique=oblique + found.group(1))
    # A genitive before a noun that a postposition follows takes the oblique too:
    # "v1 کا pids cgroup نے" for "v1 کے pids cgroup نے".
    genitive = re.compile(r"(?<!\w)کا ((?:[A-Za-z_§0][\w§]* ){1,2})(نے|کو)(?!\w)")
    found = genitive.search(bare)
    if found:
        yield found.group(0), _(
            "{found!r}: a postposition takes the oblique case, {oblique}").format(
            found=found.group(0), oblique="کے " + found.group(1) + found.group(2))


# --- README blocks -------------------------------------------------------------------
_BLOCK_MARK = re.compile(r"^\s*(?:#{1,6}|[-*+]|\d+[.)]|>)\s+")
_HTML_TAG = re.compile(r"<[^>]+>")


def first_strong(text: str) -> str | None:
    """``"L"`` or ``"R"``: the bidi class of the first strong character, if any."""
    for char in text:
        kind = unicodedata.bidirectional(char)
        if kind == "L":
            return "L"
        if kind in ("R", "AL"):
            return "R"
    return None


def block_starts_latin(line: str) -> str | None:
    """The start of a Markdown block (a heading, paragraph or list item) whose first strong
    character is Latin though it holds Urdu: GitHub lays each such block out by its first
    strong character (``dir="auto"``), whatever the wrapping ``<div dir>`` says.  Table
    cells carry no ``dir="auto"`` and take the wrapper's direction."""
    if line.lstrip().startswith("|"):
        return None
    body = _HTML_TAG.sub("", _BLOCK_MARK.sub("", line)).replace("**", "").replace("*", "")
    if first_strong(body) == "L" and any(
            unicodedata.bidirectional(c) in ("R", "AL") for c in body):
        return body.strip()[:40]
    return None
