"""``autograder quiz serve``: a small local web server for taking quizzes in a browser.

Standard library only (``http.server``), one request at a time, bound to 127.0.0.1.
The key stays here: pages carry questions and option ids, the score is computed on POST.
"""

from __future__ import annotations

import secrets
import traceback
from collections.abc import Mapping
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, HTTPServer
from typing import Any
from urllib.parse import parse_qs, urlsplit

from markupsafe import escape

from autograder.core.errors import ContentError
from autograder.i18n import LANGUAGES, _
from autograder.i18n.text import using_language
from autograder.quiz.model import Quiz, QuizFile
from autograder.quiz.render import render_index, render_page, render_result
from autograder.quiz.scoring import check_answers, score
from autograder.quiz.types import question_type

HOST = "127.0.0.1"


def form_answers(quiz: Quiz, form: Mapping[str, list[str]]) -> dict[str, Any]:
    """Answers from a submitted form, in the answers-file shape; blanks are left out."""
    answers: dict[str, Any] = {}
    for q in quiz.questions:
        value = question_type(q.type).parse_form(q, form)
        if value is not None:
            answers[q.id] = value
    return answers


def _submit_url(quiz: Quiz) -> str:
    return f"/quiz/{quiz.id}/submit"


class QuizServer(HTTPServer):
    """An HTTP server that knows the course's quizzes."""

    def __init__(self, quizzes: list[QuizFile], port: int = 0, lang: str = "en") -> None:
        self.quizzes = {qf.quiz.id: qf.quiz for qf in quizzes}
        self.default_lang = lang
        super().__init__((HOST, port), _Handler)

    @property
    def url(self) -> str:
        return f"http://{HOST}:{self.server_address[1]}/"


class _Handler(BaseHTTPRequestHandler):
    server: QuizServer

    def log_message(self, format: str, *args: Any) -> None:  # stdlib name
        pass  # quiet: a student's terminal is not an access log

    def _send(self, status: HTTPStatus, body: str) -> None:
        data = body.encode("utf-8")
        self.send_response(status)
        self.send_header("Content-Type", "text/html; charset=utf-8")
        self.send_header("Content-Length", str(len(data)))
        self.send_header("Cache-Control", "no-store")
        self.end_headers()
        self.wfile.write(data)

    def _lang(self, query: Mapping[str, list[str]]) -> str:
        lang = query.get("lang", [self.server.default_lang])[0]
        return lang if lang in LANGUAGES else self.server.default_lang

    def _error(self, status: HTTPStatus, message: str, lang: str) -> None:
        page = (f'<!doctype html><html lang="{lang}" dir="{"rtl" if lang == "ur" else "ltr"}">'
                f'<meta charset="utf-8"><title>{int(status)}</title>'
                f'<p id="error">{escape(message)}</p></html>')
        self._send(status, page)

    def _route(self) -> tuple[Quiz | None, str, dict[str, list[str]]]:
        parts = urlsplit(self.path)
        query = parse_qs(parts.query)
        segments = [s for s in parts.path.split("/") if s]
        quiz = None
        if len(segments) >= 2 and segments[0] == "quiz":
            quiz = self.server.quizzes.get(segments[1])
        return quiz, "/".join(segments[2:]), query

    def do_GET(self) -> None:  # http.server's name
        quiz, rest, query = self._route()
        lang = self._lang(query)
        with using_language(lang):
            try:
                if self.path.split("?")[0] == "/":
                    quizzes = list(self.server.quizzes.values())
                    self._send(HTTPStatus.OK, render_index(quizzes, lang, LANGUAGES))
                elif quiz is not None and rest in ("", "submit"):  # submit: a reload
                    seed = secrets.randbelow(10**9)  # a fresh option order per attempt
                    # Absolute: /quiz/ID and /quiz/ID/ both post to /quiz/ID/submit.
                    self._send(HTTPStatus.OK, render_page(quiz, lang, seed,
                                                          action=_submit_url(quiz)))
                else:
                    self._error(HTTPStatus.NOT_FOUND, _("Not found."), lang)
            except Exception:  # our bug, not the student's: say so, keep serving
                traceback.print_exc()
                self._error(HTTPStatus.INTERNAL_SERVER_ERROR,
                            _("The autograder failed, tell your instructor."), lang)

    def do_POST(self) -> None:  # http.server's name
        quiz, rest, query = self._route()
        length = min(int(self.headers.get("Content-Length") or 0), 1_000_000)
        form = parse_qs(self.rfile.read(length).decode("utf-8", "replace"))
        lang = self._lang(form) if "lang" in form else self._lang(query)
        with using_language(lang):
            if quiz is None or rest != "submit":
                self._error(HTTPStatus.NOT_FOUND, _("Not found."), lang)
                return
            seed = form.get("seed", [""])[0] or None
            problems = {q.id: problem for q in quiz.questions
                        if (problem := question_type(q.type).form_problem(q, form))}
            if problems:  # the page again, the answers kept, each problem at its question
                self._send(HTTPStatus.BAD_REQUEST, render_page(
                    quiz, lang, seed, action=_submit_url(quiz), given=form, problems=problems))
                return
            try:
                answers = check_answers("<form>", quiz, {"quiz": quiz.id,
                                                         "answers": form_answers(quiz, form)})
                result = score(quiz, answers, lang)
                self._send(HTTPStatus.OK, render_result(quiz, result, answers, seed))
            except ContentError as exc:
                self._error(HTTPStatus.BAD_REQUEST, exc.message, lang)
            except Exception:
                traceback.print_exc()
                self._error(HTTPStatus.INTERNAL_SERVER_ERROR,
                            _("The autograder failed, tell your instructor."), lang)
