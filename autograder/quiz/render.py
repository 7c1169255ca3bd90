"""What a student receives: an HTML page, a Markdown/MDX export, terminal text.

Everything here is built from *views* that carry no answer key (``question_views``), so
no renderer can leak it.  HTML comes from autoescaped Jinja2 templates; what is particular
to a question type (its inputs, its Markdown) comes from the type.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

from autograder.core.results import RunResult
from autograder.i18n import _, is_rtl
from autograder.i18n.templates import environment
from autograder.i18n.text import (
    Text,
    format_number,
    format_percent,
    markdown_inline,
    plain,
    using_language,
)
from autograder.quiz.localize import Localizer
from autograder.quiz.model import Quiz
from autograder.quiz.scoring import pass_summary
from autograder.quiz.types import question_type
from autograder.quiz.views import question_views


def _page_context(quiz: Quiz, lang: str) -> dict[str, Any]:
    loc = Localizer(quiz, lang)
    return {
        "lang": lang,
        "dir": "rtl" if is_rtl(lang) else "ltr",
        "quiz_id": quiz.id,
        "title": loc.quiz_text("title"),
        "summary": loc.quiz_text("summary") if quiz.summary else None,
        "pass_summary": pass_summary(quiz, lang),
    }


def render_page(quiz: Quiz, lang: str, seed: str | int | None = None,
                action: str | None = None, languages: tuple[str, ...] = (),
                given: Mapping[str, list[str]] | None = None,
                problems: Mapping[str, str] | None = None) -> str:
    """The quiz page; with ``action`` the form posts there, else answers save to a file.
    ``given`` (a submitted form) fills the answers back in; ``problems`` says at each
    question id why what was entered is no answer."""
    with using_language(lang):
        return environment().get_template("quiz.html").render(
            **_page_context(quiz, lang), questions=question_views(quiz, lang, seed),
            seed="" if seed is None else str(seed), action=action,
            languages=languages or quiz.languages, given=given or {},
            problems=problems or {})


def render_result(quiz: Quiz, result: RunResult, answers: Mapping[str, Any],
                  seed: str | int | None = None, retake: bool = True) -> str:
    """The page a student sees after submitting: score, verdict, per-question feedback;
    ``retake``: with a link to take the quiz again (served pages only)."""
    lang = result.lang
    saved = {"quiz": quiz.id, "answers": dict(answers)}
    if seed is not None:
        saved["seed"] = seed
    with using_language(lang):
        return environment().get_template("quiz_result.html").render(
            **_page_context(quiz, lang), result=result,
            score=format_number(result.score, lang),
            max_score=format_number(result.max_score, lang),
            percent=format_percent(result.fraction, lang),
            feedback=_feedback(quiz, result), retake=retake,
            answers_json=json.dumps(saved, ensure_ascii=False, indent=2))


def _feedback(quiz: Quiz, result: RunResult
              ) -> list[tuple[Any, Text, Text | None, Text | None]]:
    """Per question: its result, its text, its explanation and the student's own answer
    as they read it back (the options they chose, the number they gave), as the terminal
    shows it; None where they gave none."""
    loc = Localizer(quiz, result.lang)
    rows = []
    for t in result.tests:
        q = quiz.question(t.name)
        assert q is not None, t.name
        given = t.answer
        answer = None if given is None else Text(
            question_type(q.type).answer_text(quiz, q, given, loc), result.lang)
        rows.append((t, loc.text(q, "text"),
                     loc.text(q, "explanation") if q.explanation else None, answer))
    return rows


def render_index(quizzes: list[Quiz], lang: str, languages: tuple[str, ...]) -> str:
    """The server's home page: pick a language and a quiz."""
    with using_language(lang):
        items = [(q, Localizer(q, lang).quiz_text("title")) for q in quizzes]
        return environment().get_template("quiz_index.html").render(
            lang=lang, dir="rtl" if is_rtl(lang) else "ltr", items=items,
            languages=languages, title=Text(_("Quizzes"), lang))


# Markdown / MDX ---------------------------------------------------------------------------


def render_markdown(quiz: Quiz, lang: str, seed: str | int | None = None) -> str:
    """A Markdown/MDX export for a Docusaurus page: questions and options, never the key."""
    with using_language(lang):
        ctx = _page_context(quiz, lang)
        rtl = is_rtl(lang)
        lines = ["---", f"title: {json.dumps(plain(ctx['title'], False), ensure_ascii=False)}",
                 "---", ""]
        if rtl:
            lines += [f'<div dir="rtl" lang="{lang}">', ""]
        lines += [f"# {markdown_inline(ctx['title'])}", ""]
        if ctx["summary"]:
            lines += [markdown_inline(ctx["summary"]), ""]
        lines += [f"**{markdown_inline(Text(ctx['pass_summary'], lang))}**", ""]
        for q in question_views(quiz, lang, seed):
            lines += [f"## {format_number(q.number, lang)}. {markdown_inline(q.text)}", ""]
            if q.code:
                block = ["```python", q.code, "```"]
                lines += (['<div dir="ltr">', "", *block, "", "</div>"] if rtl else block)
                lines.append("")
            lines += question_type(q.type).markdown_lines(q)
        if rtl:
            lines += ["</div>", ""]
        return "\n".join(lines)
